#include "app/live_output.h"

#include <visp3/core/vpException.h>
#include <visp3/io/vpImageIo.h>

#include <cstdio>
#include <filesystem>

#include "app/cli_common.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/trajectory_io.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;

// One TUM line (no header) for a pose at time t.
std::string TumLine(double t, const Eigen::Isometry3d& cam_from_world) {
  const std::string text = FormatTum({{t, cam_from_world.inverse()}});
  return text.substr(text.find('\n') + 1);
}

// A CSV field: quoted when it holds a comma or a quote.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '\n') c = ' ';
    out += c;
    if (c == '"') out += '"';
  }
  return out + "\"";
}

void Open(const fs::path& path, const std::string& header, std::ofstream* out) {
  out->open(path, std::ios::trunc);
  *out << header << "\n";
  out->flush();
  if (!*out) throw InputError(path.string() + ": cannot write the file");
}

}  // namespace

const char* const kLiveCsvHeader =
    "frame,t,grab,status,state,source,pan_deg,tilt_deg,pan_rate_deg_s,tilt_rate_deg_s,command,"
    "cmd_pan_rate_deg_s,cmd_tilt_rate_deg_s,error_u_px,error_v_px,error_px,gain,converged,"
    "saturated,limited,compensated,prior_x,prior_y,prior_heading_deg,prior_tilt_deg,estimate_ms,"
    "loop_ms,sigma_x_m,sigma_y_m,sigma_heading_deg,protection_level_m,protection_level_deg,note";

std::string LiveCsvRow(const LiveIteration& it) {
  char numbers[512];
  std::snprintf(
      numbers, sizeof(numbers),
      "%lld,%.6f,%s,%s,%s,%s,%.4f,%.4f,%.4f,%.4f,%s,%.4f,%.4f,%.3f,%.3f,%.3f,%.4f,%d,%d,%d,%d,"
      "%.4f,%.4f,%.3f,%.3f,%.4f,%.4f,",
      static_cast<long long>(it.frame), it.t, ToString(it.grab),
      ToString(it.estimate.uncertainty.status), ToString(it.estimate.status),
      CsvField(it.estimate.source).c_str(), RadToDeg(it.head.pan), RadToDeg(it.head.tilt),
      RadToDeg(it.head.pan_rate), RadToDeg(it.head.tilt_rate), ToString(it.command),
      RadToDeg(it.servo.pan_rate), RadToDeg(it.servo.tilt_rate), it.servo.error_u_px,
      it.servo.error_v_px, it.servo.error_px, it.servo.gain, it.servo.converged, it.servo.saturated,
      it.servo.limited, it.servo.compensated, it.camera_prior.x, it.camera_prior.y,
      RadToDeg(it.camera_prior.heading), RadToDeg(it.camera_prior.tilt), it.estimate_ms,
      it.loop_ms);
  std::string note = it.note;
  if (note.empty() && it.estimate.uncertainty.status != IntegrityStatus::kTracking) {
    note = it.estimate.note.empty() ? it.estimate.uncertainty.reason : it.estimate.note;
  }
  if (it.command != HeadCommand::kNone && !it.command_result.ok()) {
    note += (note.empty() ? "" : "; ") + std::string("head: ") + it.command_result.message;
  }
  return numbers + IntegrityCsvFields(it.estimate.uncertainty) + "," + CsvField(note);
}

LiveOutput::LiveOutput(const std::string& dir, bool with_truth, bool all_poses)
    : dir_(dir), all_poses_(all_poses) {
  EnsureDirectory(dir);
  const fs::path root(dir);
  std::error_code ec;
  fs::remove_all(root / "snapshots", ec);
  fs::remove(root / "summary.json", ec);
  fs::remove(root / "truth.txt", ec);
  Open(root / "frames.csv", kLiveCsvHeader, &frames_);
  covariance_ = std::make_unique<CovarianceLog>(dir);
  Open(root / "poses.txt", "# t x y z qx qy qz qw (world_from_cam, ViSP camera axes)", &poses_);
  if (with_truth) {
    Open(root / "truth.txt", "# t x y z qx qy qz qw (world_from_cam, ViSP camera axes)", &truth_);
  }
}

void LiveOutput::Add(const LiveIteration& it, const Eigen::Isometry3d* true_cam_from_world) {
  frames_ << LiveCsvRow(it) << "\n";
  frames_.flush();
  covariance_->Add(static_cast<long>(it.frame), it.t, it.estimate.uncertainty);
  if (it.estimate.has_pose() &&
      (all_poses_ || it.estimate.uncertainty.status == IntegrityStatus::kTracking)) {
    poses_ << TumLine(it.t, *it.estimate.cam_from_world);
    poses_.flush();
  }
  if (true_cam_from_world != nullptr && truth_.is_open()) {
    truth_ << TumLine(it.t, *true_cam_from_world);
    truth_.flush();
  }
  if (!frames_ || !poses_) throw InputError(dir_ + ": cannot write the output files");
}

void LiveOutput::Snapshot(std::int64_t frame, const vpImage<vpRGBa>& image) {
  const fs::path folder = fs::path(dir_) / "snapshots";
  EnsureDirectory(folder.string());
  char name[40];
  std::snprintf(name, sizeof(name), "frame_%05lld", static_cast<long long>(frame));
  const fs::path path = folder / (std::string(name) + ".png");
  const fs::path tmp = folder / ("." + std::string(name) + ".tmp.png");
  try {
    vpImageIo::write(image, tmp.string());
  } catch (const vpException& e) {
    throw InputError(path.string() + ": cannot write the file (" + e.getMessage() + ")");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path.string() + ": cannot write the file");
  }
}

void LiveOutput::Finish(const nlohmann::ordered_json& summary) {
  frames_.flush();
  poses_.flush();
  if (truth_.is_open()) truth_.flush();
  WriteFileAtomically((fs::path(dir_) / "summary.json").string(), summary.dump(2) + "\n");
}

}  // namespace linetrack::app

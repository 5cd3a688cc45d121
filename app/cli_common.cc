#include "app/cli_common.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "models/camera_file.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {

std::vector<double> ParseNumberList(const std::string& text, size_t count, const std::string& flag,
                                    const std::string& form) {
  std::stringstream in(text);
  std::string field;
  std::vector<double> values;
  while (std::getline(in, field, ',')) {
    if (values.size() >= count)
      throw InputError(flag + ": expected " + form + ", got '" + text + "'");
    try {
      size_t used = 0;
      values.push_back(std::stod(field, &used));
      if (used != field.size() || !std::isfinite(values.back())) throw std::invalid_argument(field);
    } catch (const std::exception&) {
      throw InputError(flag + ": not a finite number: '" + field + "' in '" + text + "'");
    }
  }
  if (values.size() != count || (!text.empty() && text.back() == ','))
    throw InputError(flag + ": expected " + form + ", got '" + text + "'");
  return values;
}

Pose3Dof ParsePrior(const std::string& text, const std::string& flag) {
  const std::vector<double> v = ParseNumberList(text, 3, flag, "X,Y,HEADING_DEG");
  return {v[0], v[1], DegToRad(v[2])};
}

std::vector<double> ParseNumbers(const std::string& text, int count, const std::string& flag) {
  return ParseNumberList(text, static_cast<size_t>(count), flag,
                         std::to_string(count) + " comma-separated numbers");
}

void CheckRange(double value, double lo, double hi, const std::string& flag) {
  if (!std::isfinite(value) || value < lo || value > hi) {
    std::ostringstream msg;
    msg << flag << ": " << value << " is outside [" << lo << ", " << hi << "]";
    throw InputError(msg.str());
  }
}

void CheckTimesOverlap(const std::vector<double>& times, double first, double last,
                       double tolerance, const std::string& what) {
  if (times.empty()) return;
  const auto [lo, hi] = std::minmax_element(times.begin(), times.end());
  if (*hi >= first - tolerance && *lo <= last + tolerance) return;
  std::ostringstream msg;
  msg << std::fixed << std::setprecision(3) << what << ": its times " << *lo << "-" << *hi
      << " s do not overlap the frames' times " << first << "-" << last
      << " s (give --time-offset SECONDS, or --align-times)";
  throw InputError(msg.str());
}

void CheckHeight(double metres, const std::string& flag) {
  if (!std::isfinite(metres) || metres <= 0.0 || metres > 100.0) {
    std::ostringstream msg;
    msg << flag << ": " << metres
        << " is not a camera height (metres above the floor: more than 0, at most 100)";
    throw InputError(msg.str());
  }
}

void RefuseUnless(const CLI::App& cmd, bool applies, const std::vector<std::string>& flags,
                  const std::string& why) {
  if (applies) return;
  for (const std::string& flag : flags) {
    if (cmd.count(flag) > 0) throw CLI::ValidationError(flag, why);
  }
}

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << content;
    out.flush();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw InputError(path + ": cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path + ": cannot write the file");
  }
}

CLI::App* BenchGroup(CLI::App& cli) {
  const auto found = cli.get_subcommands([](CLI::App* s) { return s->get_name() == "bench"; });
  if (!found.empty()) return found.front();
  CLI::App* bench = cli.add_subcommand(
      "bench", "Benchmarks: accuracy and speed figures on this machine (see docs/)");
  bench->require_subcommand(1);
  return bench;
}

namespace {

std::atomic<int> g_stop_signal{0};

extern "C" void RecordStopSignal(int signal) {
  g_stop_signal = signal;
}

}  // namespace

struct StopSignals::Saved {
  struct sigaction old_int {};
  struct sigaction old_term {};
};

StopSignals::StopSignals() : saved_(std::make_unique<Saved>()) {
  g_stop_signal = 0;
  struct sigaction action {};
  action.sa_handler = RecordStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &saved_->old_int);
  sigaction(SIGTERM, &action, &saved_->old_term);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &saved_->old_int, nullptr);
  sigaction(SIGTERM, &saved_->old_term, nullptr);
}

int StopSignals::Received() {
  return g_stop_signal;
}

std::string StopSignals::ReceivedName() {
  const int signal = g_stop_signal;
  if (signal == 0) return "";
  return signal == SIGINT ? "SIGINT" : "SIGTERM";
}

void EnsureDirectory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(dir + ": cannot create the output folder");
  }
}

CameraIntrinsics LoadCamera(const std::string& path, const std::string& name) {
  const CameraFile file = ReadCameraFile(path, name);
  if (file.format != CameraFileFormat::kVispXml && !file.brown_conrady.IsZero()) {
    // A pixel error of this size would bias the tracked poses: say so louder.
    constexpr double kLoudErrorPx = 1.0;
    const std::string text = fmt::format(
        "{}: {}: its distortion (k1 k2 p1 p2 k3) is used as ViSP's one-term model (kud {:.5f}, "
        "kdu {:.5f}), within {:.2f} px over the image",
        path, ToString(file.format), file.camera.kud, file.camera.kdu, file.approximation_px);
    if (file.approximation_px > kLoudErrorPx) {
      spdlog::warn("{}; a ViSP calibration (calibrate's camera.xml) fits the images better", text);
    } else {
      spdlog::info("{}", text);
    }
  }
  return file.camera;
}

}  // namespace linetrack::app

// `linetrack bench mount`: the accuracy of `calibrate-mount`'s live mode on the simulator over
// seeded runs. Each seed puts the simulated bracket off the nominal PTU-46 mount by a shift and a
// rotation vector drawn uniformly within +-(--bracket-mm, --bracket-deg) per axis of the tilt
// frame, drives the simulated head through the grid in front of the simulated chessboard,
// calibrates, and compares the mount with the truth: its position and rotation errors, and the
// normalised estimation error squared e^T C^-1 e of its reported covariance (6 expected).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>

#include "app/commands.h"
#include "app/mount_views.h"
#include "calibration/mount_calibration.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "tracking/integrity/consistency.h"

namespace linetrack::app {
namespace {

struct BenchMountCommandOptions {
  std::string camera_path;
  MountCalibrationOptions mount;
  int seeds = 5, first_seed = 1, views = 20;
  double bracket_mm = 5.0, bracket_deg = 1.5;
  double pan_range_deg = 20.0, tilt_range_deg = 12.0;
  bool json = false;
};

struct MountBenchRun {
  std::uint64_t seed = 0;
  Eigen::Matrix<double, 6, 1> bracket;  // the simulated bracket's error (metres, radians)
  MountCalibration mount;
  Eigen::Matrix<double, 6, 1> error;        // PoseDelta(estimate, truth)
  Eigen::Matrix<double, 6, 1> start_error;  // of ViSP's hand-eye start
  double nees = 0.0, seconds = 0.0;
};

// The bracket's error of `seed`: uniform within +-mm (shift) and +-deg (rotation vector) per axis.
Eigen::Matrix<double, 6, 1> DrawBracket(std::uint64_t seed, double mm, double deg) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix<double, 6, 1> bracket;
  for (int k = 0; k < 3; ++k)
    bracket[k] = 1e-3 * mm * unit(rng);
  for (int k = 3; k < 6; ++k)
    bracket[k] = DegToRad(deg) * unit(rng);
  return bracket;
}

// The simulator's flags for `bracket` and the render seed (tracking/sim/sim_camera.h).
std::string SimSpec(std::uint64_t seed, const Eigen::Matrix<double, 6, 1>& b) {
  char spec[256];
  std::snprintf(spec, sizeof(spec),
                "sim:seed=%llu,bracket_mm=%.6f:%.6f:%.6f,bracket_deg=%.6f:%.6f:%.6f",
                static_cast<unsigned long long>(seed), 1e3 * b[0], 1e3 * b[1], 1e3 * b[2],
                RadToDeg(b[3]), RadToDeg(b[4]), RadToDeg(b[5]));
  return spec;
}

MountBenchRun RunSeed(const BenchMountCommandOptions& opt, const CameraIntrinsics& camera,
                      std::uint64_t seed) {
  const auto start = std::chrono::steady_clock::now();
  MountBenchRun run;
  run.seed = seed;
  run.bracket = DrawBracket(seed, opt.bracket_mm, opt.bracket_deg);
  MountViewsPlan plan;
  plan.source_spec = SimSpec(seed, run.bracket);
  plan.head_spec = "sim";
  plan.angles = SweepGrid(
      Eigen::Vector2d::Zero(),
      Eigen::Vector2d(DegToRad(opt.pan_range_deg), DegToRad(opt.tilt_range_deg)), opt.views);
  const MountViews views = GrabMountViews(plan, opt.mount.pattern, camera);
  std::vector<PatternDetection> detections;
  for (const cv::Mat& image : views.images)
    detections.push_back(DetectPattern(image, opt.mount.pattern, opt.mount.detection));
  MountCalibrationOptions options = opt.mount;
  options.distortion = views.distortion;
  run.mount = CalibrateMountFromDetections(views.names, views.angles, detections, camera, options);
  const Eigen::Isometry3d truth =
      MovedPose(GeometryOf(HeadModel::kPtu46).tilt_from_camera, run.bracket);
  if (run.mount.ok()) {
    run.error = PoseDelta(run.mount.tilt_from_camera, truth);
    run.start_error = PoseDelta(run.mount.hand_eye_start, truth);
    run.nees = Nees(run.error, run.mount.covariance);
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

nlohmann::ordered_json ToJson(const MountBenchRun& r) {
  const Eigen::Matrix<double, 6, 1> sigma = r.mount.covariance.diagonal().cwiseSqrt();
  return {{"seed", r.seed},
          {"ok", r.mount.ok()},
          {"message", r.mount.message},
          {"bracket_mm", 1e3 * r.bracket.head<3>().norm()},
          {"bracket_deg", RadToDeg(r.bracket.tail<3>().norm())},
          {"views_used", r.mount.UsedViews()},
          {"rms_px", r.mount.rms_px},
          {"position_error_mm", 1e3 * r.error.head<3>().norm()},
          {"rotation_error_deg", RadToDeg(r.error.tail<3>().norm())},
          {"position_sigma_mm", 1e3 * sigma.head<3>().norm()},
          {"rotation_sigma_deg", RadToDeg(sigma.tail<3>().norm())},
          {"nees", r.nees},
          {"noise_px", r.mount.noise_sigma_px},
          {"view_shift_px", r.mount.view_shift_px},
          {"hand_eye_position_error_mm", 1e3 * r.start_error.head<3>().norm()},
          {"hand_eye_rotation_error_deg", RadToDeg(r.start_error.tail<3>().norm())},
          {"seconds", r.seconds}};
}

void PrintTable(const std::vector<MountBenchRun>& runs) {
  std::printf(
      "seed  bracket mm  deg  views  RMS px  error mm  error deg  sigma mm  sigma deg   NEES  "
      "ViSP start mm  deg     s\n");
  double max_mm = 0.0, max_deg = 0.0, nees_sum = 0.0;
  int ok = 0;
  for (const MountBenchRun& r : runs) {
    if (!r.mount.ok()) {
      std::printf("%4llu  failed: %s\n", static_cast<unsigned long long>(r.seed),
                  r.mount.message.c_str());
      continue;
    }
    const Eigen::Matrix<double, 6, 1> sigma = r.mount.covariance.diagonal().cwiseSqrt();
    const double mm = 1e3 * r.error.head<3>().norm(), deg = RadToDeg(r.error.tail<3>().norm());
    std::printf(
        "%4llu  %10.2f %4.2f  %5d  %6.3f  %8.3f  %9.4f  %8.3f  %9.4f  %5.2f  %13.3f  %5.3f  "
        "%4.0f\n",
        static_cast<unsigned long long>(r.seed), 1e3 * r.bracket.head<3>().norm(),
        RadToDeg(r.bracket.tail<3>().norm()), r.mount.UsedViews(), r.mount.rms_px, mm, deg,
        1e3 * sigma.head<3>().norm(), RadToDeg(sigma.tail<3>().norm()), r.nees,
        1e3 * r.start_error.head<3>().norm(), RadToDeg(r.start_error.tail<3>().norm()), r.seconds);
    max_mm = std::max(max_mm, mm);
    max_deg = std::max(max_deg, deg);
    nees_sum += r.nees;
    ++ok;
  }
  std::printf(
      "%d of %zu seeds calibrated; largest error %.3f mm, %.4f deg; mean NEES %.2f "
      "(6 expected for a consistent covariance)\n",
      ok, runs.size(), max_mm, max_deg, ok > 0 ? nees_sum / ok : 0.0);
}

int RunBenchMount(BenchMountCommandOptions opt) {
  if (opt.seeds < 1) throw InputError("--seeds: must be >= 1");
  if (opt.first_seed < 0) throw InputError("--first-seed: must be >= 0");
  if (opt.views < 4) throw InputError("--views: must be >= 4");
  CheckRange(opt.bracket_mm, 0.0, 50.0, "--bracket-mm");
  CheckRange(opt.bracket_deg, 0.0, 10.0, "--bracket-deg");
  CheckRange(opt.pan_range_deg, 1.0, 90.0, "--pan-range");
  CheckRange(opt.tilt_range_deg, 1.0, 45.0, "--tilt-range");
  opt.mount.pattern.kind = PatternKind::kChessboard;
  std::string why;
  if (!opt.mount.Check(&why)) throw InputError("bench mount: " + why);
  const CameraIntrinsics camera = LoadCamera(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  std::vector<MountBenchRun> runs;
  for (int k = 0; k < opt.seeds; ++k)
    runs.push_back(RunSeed(opt, camera, static_cast<std::uint64_t>(opt.first_seed + k)));
  if (opt.json) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const MountBenchRun& r : runs)
      out.push_back(ToJson(r));
    std::cout << out.dump(2) << std::endl;
  } else {
    PrintTable(runs);
  }
  for (const MountBenchRun& r : runs)
    if (!r.mount.ok()) return kExitJobFailed;
  return kExitOk;
}

}  // namespace

void AddBenchMount(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchMountCommandOptions>();
  opt->mount.pattern.square = 0.04;
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "mount",
      "Accuracy of calibrate-mount on the simulator over seeded runs: the simulated bracket off "
      "the nominal PTU-46 mount at random, the head swept in front of a chessboard; the mount's "
      "position and rotation errors against the truth and the NEES of its covariance");
  cmd->add_option("--camera", opt->camera_path,
                  "Camera file: ViSP XML, OpenCV or ROS YAML, with its image size")
      ->required();
  cmd->add_option("--cols", opt->mount.pattern.cols, "Chessboard inner corners per row")
      ->capture_default_str();
  cmd->add_option("--rows", opt->mount.pattern.rows, "Chessboard inner corners per column")
      ->capture_default_str();
  cmd->add_option("--square", opt->mount.pattern.square, "Square side (metres)")
      ->capture_default_str();
  cmd->add_option("--seeds", opt->seeds, "Runs")->capture_default_str();
  cmd->add_option("--first-seed", opt->first_seed, "Seed of the first run")->capture_default_str();
  cmd->add_option("--views", opt->views, "Head angles per run (at least)")->capture_default_str();
  cmd->add_option("--pan-range", opt->pan_range_deg, "Grid half-range of pan (degrees)")
      ->capture_default_str();
  cmd->add_option("--tilt-range", opt->tilt_range_deg, "Grid half-range of tilt (degrees)")
      ->capture_default_str();
  cmd->add_option("--bracket-mm", opt->bracket_mm, "Bracket shift bound per axis (mm)")
      ->capture_default_str();
  cmd->add_option("--bracket-deg", opt->bracket_deg,
                  "Bracket rotation bound per axis (degrees, rotation vector)")
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "One JSON object per run instead of the table");
  cmd->callback([opt, action] { *action = [opt] { return RunBenchMount(*opt); }; });
}

}  // namespace linetrack::app

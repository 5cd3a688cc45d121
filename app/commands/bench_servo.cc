// `linetrack bench servo`: the live loop on the simulator. Time per loop iteration excluding
// capture (head read, pose estimate, servo law, head command), and the servo's accuracy from a
// 10/5 degree offset (robot standing) and while the robot drives one lap of the loop.
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench/servo_bench.h"
#include "app/commands.h"
#include "app/localize_image.h"
#include "app/model_loading.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

struct BenchServoCommandOptions {
  std::string model_path, camera_path, nav_path;
  ServoBenchOptions bench;
  double jitter_deg = 0.0, jitter_m = 0.0;
  std::string estimator = "tracker";
  std::string settings;
  bool no_feed_forward = false;
  bool json = false;
};

double PassesPerFrame(const ServoBenchRun& r) {
  return r.frames > 0 ? static_cast<double>(r.tracking_passes) / r.frames : 0.0;
}

nlohmann::ordered_json ToJson(const ServoBenchRun& r) {
  return {{"run", r.name},
          {"frames", r.frames},
          {"start_error_px", r.start_error_px},
          {"convergence_s", r.convergence_s},
          {"final_error_px", r.final_error_px},
          {"frames_with_pose", r.frames_with_pose},
          {"max_position_error_m", r.max_position_error_m},
          {"max_rotation_error_deg", r.max_rotation_error_deg},
          {"settle_s", r.settle_s},
          {"mean_error_px", r.mean_error_px},
          {"p95_error_px", r.p95_error_px},
          {"max_error_px", r.max_error_px},
          {"loop_ms_median", QuantileNearestRank(r.loop_ms, 0.5)},
          {"loop_ms_p95", QuantileNearestRank(r.loop_ms, 0.95)},
          {"loop_ms_max", QuantileNearestRank(r.loop_ms, 1.0)},
          {"estimate_ms_median", QuantileNearestRank(r.estimate_ms, 0.5)},
          {"capture_ms_median", QuantileNearestRank(r.grab_ms, 0.5)},
          {"tracker_stages_ms_median",
           {{"undistort", QuantileNearestRank(r.undistort_ms, 0.5)},
            {"predict", QuantileNearestRank(r.predict_ms, 0.5)},
            {"passes", QuantileNearestRank(r.passes_ms, 0.5)},
            {"measure", QuantileNearestRank(r.measure_ms, 0.5)},
            {"relocalize", QuantileNearestRank(r.relocalize_ms, 0.5)}}},
          {"tracking_passes_per_frame", PassesPerFrame(r)}};
}

int RunBenchServo(BenchServoCommandOptions opt) {
  opt.bench.jitter.rotation_sigma = DegToRad(opt.jitter_deg);
  opt.bench.jitter.translation_sigma = opt.jitter_m;
  if (opt.no_feed_forward) opt.bench.servo.target_motion_filter = 0.0;
  if (opt.estimator != "tracker" && opt.estimator != "truth") {
    throw InputError("--estimator: expected tracker or truth, got '" + opt.estimator + "'");
  }
  opt.bench.use_tracker = opt.estimator == "tracker";
  opt.bench.tracker.matcher.noise = DetectedLineNoise();
  if (!opt.settings.empty()) opt.bench.tracker.settings = ReadTrackerSettings(opt.settings);
  std::string why;
  if (!opt.bench.Check(&why)) throw InputError("bench servo: " + why);
  const CameraIntrinsics camera = LoadCamera(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  const WireframeModel model = LoadModel(opt.model_path);
  NavigableAreaOptions area_options;
  area_options.sidecar_path = opt.nav_path;
  const NavigableArea area = NavigableArea::FromModel(model, area_options);
  const std::vector<ServoBenchRun> runs = RunServoBench(model, area, camera, opt.bench);

  if (opt.json) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ServoBenchRun& r : runs)
      out.push_back(ToJson(r));
    std::cout << out.dump(2) << std::endl;
    return kExitOk;
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(3);
  text << "camera " << camera.width << "x" << camera.height << ", " << opt.bench.fps
       << " frames/s simulated, estimator: "
       << (opt.bench.use_tracker ? "tracker" : "simulator truth")
       << (!opt.bench.use_tracker &&
                   (opt.bench.jitter.rotation_sigma > 0 || opt.bench.jitter.translation_sigma > 0)
               ? " with jitter"
               : "")
       << ", feed-forward " << (opt.no_feed_forward ? "off" : "on") << "\n";
  for (const ServoBenchRun& r : runs) {
    text << r.name << ": " << r.frames << " frames; loop (capture excluded) median "
         << QuantileNearestRank(r.loop_ms, 0.5) << " ms, 95% "
         << QuantileNearestRank(r.loop_ms, 0.95) << " ms, max "
         << QuantileNearestRank(r.loop_ms, 1.0) << " ms; estimate median "
         << QuantileNearestRank(r.estimate_ms, 0.5) << " ms; capture (render) median "
         << QuantileNearestRank(r.grab_ms, 0.5) << " ms\n";
    if (!r.passes_ms.empty()) {
      text << "  tracker stages, medians: undistortion " << QuantileNearestRank(r.undistort_ms, 0.5)
           << " ms, odometry prediction " << QuantileNearestRank(r.predict_ms, 0.5)
           << " ms, ViSP passes " << QuantileNearestRank(r.passes_ms, 0.5) << " ms ("
           << PassesPerFrame(r) << " per frame), measure and refinement "
           << QuantileNearestRank(r.measure_ms, 0.5) << " ms; re-localisation 95% "
           << QuantileNearestRank(r.relocalize_ms, 0.95) << " ms\n";
    }
    text << "  true target error: start " << r.start_error_px << " px, below 2 px at "
         << r.convergence_s << " s, final " << r.final_error_px << " px; after " << r.settle_s
         << " s mean " << r.mean_error_px << ", 95% " << r.p95_error_px << ", max "
         << r.max_error_px << " px\n";
    text << "  poses: " << r.frames_with_pose << " of " << r.frames
         << " frames; largest error against the truth " << r.max_position_error_m * 1000.0
         << " mm, " << r.max_rotation_error_deg << " deg\n";
  }
  std::cout << text.str();
  return kExitOk;
}

}  // namespace

void AddBenchServo(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchServoCommandOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "servo",
      "The live loop on the simulator: time per iteration excluding capture (tracker included), "
      "convergence from a 10/5 degree offset, target error while the robot drives the loop");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model file")->required();
  cmd->add_option("--camera", opt->camera_path,
                  "Camera file: ViSP XML, OpenCV or ROS YAML (frame size)")
      ->required();
  cmd->add_option("--nav", opt->nav_path, "Navigable-area file (default: MODEL.nav.json)");
  cmd->add_option("--fps", opt->bench.fps, "Simulated frames per second")->capture_default_str();
  cmd->add_option("--still-seconds", opt->bench.still_seconds, "Length of the convergence run")
      ->capture_default_str();
  cmd->add_option("--drive-seconds", opt->bench.drive_seconds, "Length of the driving run")
      ->capture_default_str();
  cmd->add_option("--jitter-deg", opt->jitter_deg, "Pose rotation noise per axis (degrees)")
      ->capture_default_str();
  cmd->add_option("--jitter-m", opt->jitter_m, "Pose translation noise per axis (metres)")
      ->capture_default_str();
  cmd->add_flag(
      "--no-render", [opt](std::int64_t) { opt->bench.render = false; },
      "Grey frames instead of rendered ones");
  cmd->add_flag("--no-feed-forward", opt->no_feed_forward,
                "Turn off the compensation of the target's own motion");
  cmd->add_option("--estimator", opt->estimator,
                  "tracker (rendered frames) | truth (the simulator's pose)")
      ->capture_default_str();
  cmd->add_option("--settings", opt->settings, "ViSP tracker XML (<ecm>, <face>)");
  cmd->add_flag("--json", opt->json, "Print JSON");
  cmd->callback([opt, action, cmd] {
    RefuseUnless(*cmd, opt->estimator != "truth", {"--settings"},
                 "the tracker's settings; --estimator truth uses no tracker");
    RefuseUnless(*cmd, opt->estimator == "truth", {"--jitter-deg", "--jitter-m"},
                 "noise on the simulator's poses, with --estimator truth");
    *action = [opt] { return RunBenchServo(*opt); };
  });
}

}  // namespace linetrack::app

// `linetrack live`: run on a pan-tilt head, headless.
//   linetrack live --source aravis[:ID]|v4l2:/dev/videoN|sim[:ARGS] --head ptu:/dev/ttyUSB0|sim
//                  --model M.cao --camera C.xml [--prior X,Y,HEADING | --prior-file F.csv]
//                  --height H [--target X,Y,Z] [--target-pixel U,V] --out DIR [--duration S]
// Each frame: grab, read the head, estimate the camera pose (the robot's prior: heading = base
// heading + pan, tilt from the head), servo the head onto the target, log. SIGINT/SIGTERM stop
// the head first, then the files are completed. Outputs: app/live_output.h, docs/live.md.
#include <spdlog/spdlog.h>
#include <visp3/core/vpException.h>
#include <visp3/gui/vpDisplayX.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "app/commands.h"
#include "app/global_mode_flags.h"
#include "app/integrity_output.h"
#include "app/live_output.h"
#include "app/live_session.h"
#include "app/localize_image.h"
#include "app/model_loading.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/statistics.h"
#include "models/trajectory_io.h"
#include "tracking/capture/source_factory.h"
#include "tracking/head/head_factory.h"
#include "tracking/live/live_overlay.h"
#include "tracking/sim/sim_camera.h"

namespace linetrack::app {
namespace {

struct LiveCommandOptions {
  std::string source, head, model_path, camera_path, out;
  std::string prior, prior_file, target, target_pixel, nav_path;
  std::string head_start, head_start_offset;
  std::string head_model = "ptu46";
  std::string estimator = "auto";
  std::string settings, mount;
  double height = -1.0;
  double duration = 0.0;
  bool duration_given = false;  // without --duration: 10 s for the simulator, until stopped
  int snapshot_every = 30;
  bool display = false;
  double max_rate_deg = 57.29577951308232;  // 1 rad/s
  double camera_fps = 0.0;
  IntegrityFlags integrity;
  CoastFlags coast;
  GlobalModeFlags global;  // when a lost robot switches to the global mode
};

// A window showing the overlay of every frame (X11 through ViSP), when a display answers.
class LiveWindow {
 public:
  // Opens the window on the first image; false (headless) with *why when there is no display.
  bool Open(const vpImage<vpRGBa>& first, std::string* why) {
    if (std::getenv("DISPLAY") == nullptr || *std::getenv("DISPLAY") == '\0') {
      *why = "DISPLAY is not set";
      return false;
    }
    image_ = first;
    try {
      display_ = std::make_unique<vpDisplayX>();
      display_->init(image_, -1, -1, "linetrack live");
    } catch (const vpException& e) {
      display_.reset();
      *why = e.getMessage();
      return false;
    }
    return true;
  }
  bool is_open() const { return display_ != nullptr; }
  void Show(const vpImage<vpRGBa>& image) {
    image_ = image;
    vpDisplay::display(image_);
    vpDisplay::flush(image_);
  }

 private:
  vpImage<vpRGBa> image_;
  std::unique_ptr<vpDisplayX> display_;
};

// Every flag checked before any file is read, device opened or output written.
LivePlan CheckFlags(const LiveCommandOptions& opt) {
  LivePlan plan;
  plan.source_spec = opt.source;
  plan.head_spec = opt.head;
  const SourceSpec source = ParseSourceSpec(opt.source);
  const HeadSpec head = ParseHeadSpec(opt.head);
  plan.sim = source.kind == SourceKind::kSim;
  if (plan.sim != (head.kind == HeadKind::kSim)) {
    throw InputError("--source " + opt.source + " --head " + opt.head +
                     ": the simulated camera and the simulated head go together");
  }
  if (!ParseHeadModel(opt.head_model, &plan.head_model)) {
    throw InputError("--head-model: expected ptu46 or biclops, got '" + opt.head_model + "'");
  }
  if (opt.height < 0.0 && (opt.mount.empty() || plan.sim)) {
    throw InputError("--height: needed (the camera height above the floor with the head level)");
  }
  if (opt.height >= 0.0) {
    CheckHeight(opt.height, "--height");
    CheckRange(opt.height, 0.05, 100.0, "--height");
    plan.height = opt.height;
  }
  if (!opt.prior.empty() && !opt.prior_file.empty()) {
    throw InputError("--prior and --prior-file: give one of them");
  }
  if (!opt.prior.empty()) plan.prior = ParsePrior(opt.prior, "--prior");
  if (!opt.target.empty()) {
    const std::vector<double> v = ParseNumberList(opt.target, 3, "--target", "X,Y,Z");
    plan.loop.target = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (!opt.target_pixel.empty()) {
    const std::vector<double> v = ParseNumberList(opt.target_pixel, 2, "--target-pixel", "U,V");
    plan.loop.desired_px = Eigen::Vector2d(v[0], v[1]);
  }
  if (!opt.head_start.empty() && !opt.head_start_offset.empty()) {
    throw InputError("--head-start and --head-start-offset: give one of them");
  }
  if (!opt.head_start.empty()) {
    const auto v = ParseNumberList(opt.head_start, 2, "--head-start", "PAN_DEG,TILT_DEG");
    plan.head_start = Eigen::Vector2d(DegToRad(v[0]), DegToRad(v[1]));
  }
  if (!opt.head_start_offset.empty()) {
    if (!plan.loop.target) throw InputError("--head-start-offset: needs --target");
    const auto v =
        ParseNumberList(opt.head_start_offset, 2, "--head-start-offset", "PAN_DEG,TILT_DEG");
    plan.head_start_offset = Eigen::Vector2d(DegToRad(v[0]), DegToRad(v[1]));
  }
  if (opt.snapshot_every < 0) throw InputError("--snapshot-every: must be >= 0");
  CheckRange(opt.max_rate_deg, 0.1, 360.0, "--max-rate");
  plan.loop.servo.max_pan_rate = plan.loop.servo.max_tilt_rate = DegToRad(opt.max_rate_deg);
  plan.duration = opt.duration_given ? opt.duration : (plan.sim ? 10.0 : 0.0);
  CheckRange(plan.duration, 0.0, 1e7, "--duration");
  if (opt.estimator != "auto" && opt.estimator != "tracker" && opt.estimator != "truth") {
    throw InputError("--estimator: expected auto, tracker or truth, got '" + opt.estimator + "'");
  }
  plan.use_tracker = opt.estimator != "truth";
  if (plan.use_tracker && plan.head_model == HeadModel::kBiclops) {
    throw InputError(
        "--head-model biclops: its camera is upside down (roll 180 deg), which the tracker has "
        "not been tested with; use --estimator truth with the simulator");
  }
  CheckRange(opt.camera_fps, 0.0, 1000.0, "--camera-fps");
  opt.global.Options();  // the flags checked before any file is read
  plan.camera_fps = opt.camera_fps;
  if (!plan.sim) {
    if (!plan.use_tracker) throw InputError("--estimator truth: only with --source sim");
    if (!plan.prior && opt.prior_file.empty()) {
      throw InputError("--prior or --prior-file: the matcher needs the robot's prior");
    }
    return plan;
  }
  plan.sim_camera.head_model = plan.head_model;
  plan.sim_camera.camera_height = opt.height;
  ParseSimArguments(source.argument, &plan.sim_camera);
  if (plan.sim_camera.path == SimPath::kLoop && plan.prior) {
    throw InputError("--prior: the simulated robot drives the loop (sim:path=loop); leave it out");
  }
  if (plan.sim_camera.path == SimPath::kStill && !plan.prior) {
    throw InputError("--prior: the simulated robot stands at the prior X,Y,HEADING; give it");
  }
  if (!opt.prior_file.empty()) {
    throw InputError("--prior-file: the simulated robot has its own odometry; leave it out");
  }
  if (plan.prior) plan.sim_camera.still_base = *plan.prior;
  return plan;
}

nlohmann::ordered_json SummaryJson(const LiveSummary& s, const std::string& stop_reason) {
  const double p50 = QuantileNearestRank(s.loop_ms, 0.5),
               p95 = QuantileNearestRank(s.loop_ms, 0.95);
  return {
      {"stop_reason", stop_reason},
      {"interrupted", stop_reason.rfind("signal", 0) == 0},
      {"iterations", s.iterations},
      {"frames", s.frames},
      {"seconds", s.last_t - s.start_t},
      {"frames_with_pose", s.with_pose},
      {"frames_without_pose", s.without_pose},
      {"losses", s.losses},
      {"recoveries", s.recoveries},
      {"timeouts", s.timeouts},
      {"device_lost", s.device_lost},
      {"head_errors", s.head_errors},
      {"head_stops", s.stops},
      {"converged_frames", s.converged_frames},
      {"first_convergence_s", s.first_convergence_t < 0 ? -1.0 : s.first_convergence_t - s.start_t},
      {"final_error_px", s.final_error_px},
      {"max_error_after_convergence_px", s.max_error_after_convergence_px},
      {"saturated_frames", s.saturated_frames},
      {"limited_frames", s.limited_frames},
      {"max_cmd_pan_rate_deg_s", RadToDeg(s.max_abs_pan_rate)},
      {"max_cmd_tilt_rate_deg_s", RadToDeg(s.max_abs_tilt_rate)},
      {"pan_range_deg", {RadToDeg(s.pan_min), RadToDeg(s.pan_max)}},
      {"tilt_range_deg", {RadToDeg(s.tilt_min), RadToDeg(s.tilt_max)}},
      {"loop_ms_median", p50},
      {"loop_ms_p95", p95}};
}

// The files a live run reads, loaded and checked; inputs() points into this object.
class LiveFiles {
 public:
  LiveFiles(const LiveCommandOptions& opt, const LivePlan& plan)
      : camera_(ReadLiveCamera(opt.camera_path)), model_(LoadModel(opt.model_path)) {
    inputs_.camera = camera_;
    inputs_.model = &model_;
    if (!opt.prior_file.empty()) inputs_.priors = ReadPriors(opt.prior_file);
    if (!opt.mount.empty()) inputs_.mount = ReadMountFile(opt.mount);
    inputs_.mount_path = opt.mount;
    if (!opt.prior_file.empty() && inputs_.priors.empty()) {
      throw InputError(opt.prior_file + ": no prior rows");
    }
    inputs_.tracker.matcher.noise = DetectedLineNoise();
    inputs_.tracker.sequence.integrity = opt.integrity.Options();
    inputs_.tracker.sequence.coast = opt.coast.Options();
    inputs_.tracker.sequence.global = opt.global.Options();
    if (!opt.settings.empty()) inputs_.tracker.settings = ReadTrackerSettings(opt.settings);
    if (plan.use_tracker || plan.sim_camera.path == SimPath::kLoop ||
        plan.sim_camera.render_options.scene.clutter > 0) {
      NavigableAreaOptions area_options;
      area_options.sidecar_path = opt.nav_path;
      area_ = NavigableArea::FromModel(model_, area_options);
      inputs_.area = &*area_;
    }
  }
  LiveFiles(const LiveFiles&) = delete;
  LiveFiles& operator=(const LiveFiles&) = delete;

  const LiveInputs& inputs() const { return inputs_; }
  const WireframeModel& model() const { return model_; }

 private:
  static CameraIntrinsics ReadLiveCamera(const std::string& path) {
    CameraIntrinsics camera = LoadCamera(path);
    if (camera.width <= 0) throw InputError(path + ": the camera file gives no image size");
    return camera;
  }

  CameraIntrinsics camera_;
  WireframeModel model_;
  std::optional<NavigableArea> area_;
  LiveInputs inputs_;
};

// The overlays of a live run: a snapshot every --snapshot-every frames, and every frame in the
// window when --display finds one.
class LiveViews {
 public:
  LiveViews(const LiveCommandOptions& opt, const WireframeModel& model,
            const CameraIntrinsics& camera)
      : snapshot_every_(opt.snapshot_every),
        display_(opt.display),
        model_(model),
        camera_(camera),
        occlusion_(model) {}

  // Draws the overlay of `it` when a snapshot or the window wants it.
  void Show(const LiveIteration& it, LiveLoop& loop, LiveOutput* output) {
    const bool snapshot = snapshot_every_ > 0 && it.frame >= 0 && it.frame % snapshot_every_ == 0;
    const bool show = it.frame >= 0 && (window_.is_open() || (display_ && !window_tried_));
    if (!snapshot && !show) return;
    const vpImage<vpRGBa> overlay =
        DrawLiveOverlay(loop.last_frame().image, it,
                        it.estimate.has_pose()
                            ? ProjectVisibleEdges(model_, occlusion_, *it.estimate.cam_from_world,
                                                  camera_.Undistorted())
                            : std::vector<ProjectedEdge>(),
                        camera_, loop.desired_px());
    if (snapshot) output->Snapshot(it.frame, overlay);
    if (show && !window_tried_) {
      window_tried_ = true;
      std::string why;
      if (!window_.Open(overlay, &why)) spdlog::warn("--display: no window ({}): headless", why);
    }
    if (window_.is_open()) window_.Show(overlay);
  }

 private:
  int snapshot_every_;
  bool display_;
  const WireframeModel& model_;
  const CameraIntrinsics& camera_;
  const OcclusionTester occlusion_;
  LiveWindow window_;
  bool window_tried_ = false;
};

// How a live run's loop ended.
struct LiveRunEnd {
  LiveSummary summary;
  std::string stop_reason = "duration";
  HeadResult stopped;          // the head's stop at the end
  std::exception_ptr failure;  // an error in the middle of the run, rethrown after the files
  IntegrityTally integrity;    // statuses and sigmas, with a simulator's truth the failures
};

// Steps the loop until the duration, the end of the source, a signal or an error; then stops
// the head first.
LiveRunEnd RunLoop(const LivePlan& plan, LiveSession* session, LiveViews* views,
                   LiveOutput* output) {
  LiveLoop& loop = session->loop();
  LiveRunEnd end;
  // Simulated time: the duration is a number of frames; real devices: wall-clock seconds. 0: until
  // stopped (or the end of a recorded source).
  const std::int64_t max_frames = plan.sim ? std::llround(plan.duration * plan.sim_camera.fps) : 0;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(plan.duration));
  StopSignals signals;
  try {
    while (true) {
      if (StopSignals::Received() != 0) {
        end.stop_reason = "signal " + StopSignals::ReceivedName();
        break;
      }
      const LiveIteration it = loop.Step();
      if (it.grab == FrameStatus::kEndOfStream) {
        end.stop_reason = "end of stream";
        break;
      }
      end.summary.Add(it);
      if (end.summary.frames == 1 && it.grab == FrameStatus::kOk) {
        spdlog::info("live: first frame: t {:.3f} s, {}", it.t, ToString(it.estimate.status));
      }
      output->Add(it, session->truth());
      std::optional<IntegrityCheck> check;
      if (it.estimate.has_pose() && session->truth() != nullptr) {
        check = CheckAgainstTruth(it.estimate.uncertainty, *it.estimate.cam_from_world,
                                  *session->truth(), /*robot=*/true);
      }
      end.integrity.Add(it.estimate.uncertainty, check);
      views->Show(it, loop, output);
      if (max_frames > 0 && end.summary.frames >= max_frames) break;
      if (!plan.sim && plan.duration > 0.0 && std::chrono::steady_clock::now() >= deadline) break;
    }
  } catch (const std::exception& e) {
    // A failure in the middle of a run (a frame of the wrong size, a file that cannot be
    // written): stop the head, complete the files, then report it.
    end.failure = std::current_exception();
    end.stop_reason = std::string("error: ") + e.what();
  }
  end.stopped = loop.SafeStop();  // the head first, then the files
  if (!end.stopped.ok()) spdlog::error("head: could not stop: {}", end.stopped.message);
  return end;
}

// summary.json of the run: the loop's figures, how it stopped, what it ran on.
nlohmann::ordered_json RunSummaryJson(const LiveRunEnd& end, LiveSession& session,
                                      const IntegrityOptions& integrity) {
  nlohmann::ordered_json json = SummaryJson(end.summary, end.stop_reason);
  json["head_stopped_at_end"] = end.stopped.ok();
  json["source"] = session.DescribeSource();
  json["head"] = session.DescribeHead();
  json["estimator"] = session.DescribeEstimator();
  json["mount"] = session.DescribeMount();
  LiveLoop& loop = session.loop();
  if (loop.target()) json["target"] = {loop.target()->x(), loop.target()->y(), loop.target()->z()};
  json["target_pixel"] = {loop.desired_px().x(), loop.desired_px().y()};
  json["integrity"] = end.integrity.Summary(integrity);
  return json;
}

int RunLive(const LiveCommandOptions& opt) {
  const LivePlan plan = CheckFlags(opt);
  const LiveFiles files(opt, plan);
  LiveSession session(plan, files.inputs());
  LiveOutput output(opt.out, /*with_truth=*/session.truth() != nullptr, opt.integrity.all_poses);
  spdlog::info("live: started: source {}, head {}, estimator {}, {} s", session.DescribeSource(),
               session.DescribeHead(), session.DescribeEstimator(), plan.duration);
  LiveViews views(opt, files.model(), files.inputs().camera);
  const LiveRunEnd end = RunLoop(plan, &session, &views, &output);
  output.Finish(RunSummaryJson(end, session, files.inputs().tracker.sequence.integrity));
  if (end.failure) std::rethrow_exception(end.failure);
  std::cout << "live: " << end.summary.frames << " frames, " << end.summary.with_pose
            << " with a pose, final error " << end.summary.final_error_px << " px, stopped by "
            << end.stop_reason << "; wrote " << opt.out << std::endl;
  return end.summary.with_pose > 0 ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddLive(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<LiveCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "live",
      "Run live on a pan-tilt head, headless: grab frames, estimate the camera pose, servo the "
      "head to keep the target at the image centre, and log everything to --out");
  cmd->add_option("--source", opt->source,
                  "aravis[:ID] | v4l2:/dev/videoN | sim[:key=value,...] | video or image sequence "
                  "(docs/live.md)")
      ->required();
  cmd->add_option("--head", opt->head, "ptu:/dev/ttyUSB0 | sim")->required();
  cmd->add_option("--model", opt->model_path, "ViSP .cao model file")->required();
  cmd->add_option("--camera", opt->camera_path,
                  "Camera file: ViSP XML, OpenCV or ROS YAML (with its image size)")
      ->required();
  cmd->add_option("--height", opt->height,
                  "Camera height above the floor, head level (metres; with a --mount that has a "
                  "floor calibration it may be left out)");
  cmd->add_option("--mount", opt->mount,
                  "mount.json of linetrack calibrate-mount: the calibrated camera mount (and its "
                  "floor height) instead of --head-model's nominal geometry (and --height)");
  cmd->add_option("--out", opt->out, "Output folder")->required();
  cmd->add_option(
      "--prior", opt->prior,
      "Robot base position and heading X,Y,HEADING_DEG (the camera heading adds the pan)");
  cmd->add_option("--prior-file", opt->prior_file,
                  "Base odometry CSV t,x,y,heading_deg,height,tilt_deg (t from the first frame)");
  cmd->add_option("--target", opt->target,
                  "World point X,Y,Z to keep in view (default: centroid of the visible model)");
  cmd->add_option("--target-pixel", opt->target_pixel,
                  "Pixel U,V to bring the target to (default: the principal point)");
  cmd->add_option("--duration", opt->duration,
                  "Seconds to run (simulated seconds for sim; default 10 for sim, until Ctrl-C)");
  cmd->add_option("--head-model", opt->head_model, "Head kinematics: ptu46 | biclops")
      ->capture_default_str();
  cmd->add_option("--head-start", opt->head_start, "Move the head to PAN_DEG,TILT_DEG first");
  cmd->add_option("--head-start-offset", opt->head_start_offset,
                  "Start the head PAN_DEG,TILT_DEG away from looking at --target");
  cmd->add_option("--max-rate", opt->max_rate_deg, "Servo joint speed limit (deg/s)")
      ->capture_default_str();
  cmd->add_option("--snapshot-every", opt->snapshot_every,
                  "Overlay snapshot every N frames into DIR/snapshots (0: none)")
      ->capture_default_str();
  cmd->add_flag("--display", opt->display,
                "Show the overlay of every frame in a window (X11); headless when none answers");
  cmd->add_option("--nav", opt->nav_path,
                  "Navigable-area file for the matcher, sim:path=loop and clutter (default: "
                  "MODEL.nav.json, else derived from the walls)");
  cmd->add_option("--estimator", opt->estimator,
                  "Camera pose: auto (= tracker) | tracker | truth (the simulator's, sim only)")
      ->capture_default_str();
  cmd->add_option("--settings", opt->settings, "ViSP tracker XML (<ecm>, <face>)");
  AddIntegrityFlags(cmd, &opt->integrity);
  AddGlobalModeFlags(cmd, &opt->global);
  AddAllPosesFlag(cmd, &opt->integrity);
  AddCoastFlags(cmd, &opt->coast);
  cmd->add_option("--camera-fps", opt->camera_fps,
                  "Aravis cameras: frame rate to set (frames/s; 0: keep the camera's)");
  cmd->callback([opt, action, cmd] {
    opt->duration_given = cmd->get_option("--duration")->count() > 0;
    RefuseUnless(*cmd, opt->estimator != "truth", {"--settings"},
                 "the tracker's settings; --estimator truth uses no tracker");
    RefuseUnless(*cmd, opt->source.rfind("aravis", 0) == 0, {"--camera-fps"},
                 "sets the frame rate of an Aravis camera (--source aravis[:ID])");
    *action = [opt] { return RunLive(*opt); };
  });
}

}  // namespace linetrack::app

// `linetrack replay`: tracks a recorded video or image sequence against a .cao model, started by
// the matcher from a robot prior (or from a ViSP pose file), and writes DIR/poses.txt (TUM),
// DIR/frames.csv, DIR/overlay.mp4 (or PNG frames), DIR/summary.json and, with ground truth,
// DIR/error_plot.png. Files are written frame by frame; SIGINT/SIGTERM stop cleanly.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "app/commands.h"
#include "app/line_flags.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "app/replay_output.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/occlusion.h"
#include "tracking/capture/video_source.h"
#include "tracking/tracker/pose_file.h"
#include "tracking/tracker/robot_readings.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

struct ReplayOptions {
  std::string input, model, camera, prior_file, prior, init_pose, settings, ground_truth, out;
  double height = 0.0, tilt_deg = 0.0;
  bool has_height = false, has_tilt = false;  // --height, --tilt given
  double delta_t = SearchBounds().delta_t;
  double delta_phi_deg = RadToDeg(SearchBounds().delta_phi);
  double fps = 0.0;
  long max_frames = 0;
  bool overlay_png = false, no_overlay = false, scanline = false;
  LineFlags lines;  // the line extractor of the re-localisation
};

double Milliseconds(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// Ground truth: a TUM file (by time) or a printf pattern of ViSP pose files (by frame number).
class GroundTruth {
 public:
  explicit GroundTruth(const std::string& spec) : spec_(spec) {
    if (spec.empty()) return;
    if (ParseSequencePattern(spec, &pattern_)) {
      long first = 0, last = 0;
      if (!FindSequenceRange(pattern_, &first, &last)) {
        throw InputError(spec + ": --ground-truth: no pose file matches the pattern");
      }
      by_frame_ = true;
    } else {
      poses_ = ReadTum(spec);
      if (poses_.empty()) throw InputError(spec + ": --ground-truth: no poses");
    }
  }
  bool enabled() const { return !spec_.empty(); }
  std::vector<double> Times() const {
    std::vector<double> times;
    for (const StampedPose& p : poses_)
      times.push_back(p.t);
    return times;
  }
  // cam_from_world of frame `frame` taken at `t`; tolerance in seconds for TUM files.
  std::optional<Eigen::Isometry3d> At(long frame, double t, double tolerance) const {
    if (!by_frame_) return GroundTruthAt(poses_, t, tolerance);
    const std::string path =
        (std::filesystem::path(pattern_.directory) / SequenceFileName(pattern_, frame)).string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    return ReadPoseFile(path);
  }

 private:
  std::string spec_;
  SequencePattern pattern_;
  bool by_frame_ = false;
  std::vector<StampedPose> poses_;
};

// Everything a replay needs, read and checked before any output is written.
struct ReplaySetup {
  CameraIntrinsics camera;
  TrackerSettings settings;
  std::vector<PriorRecord> priors;
  std::optional<Eigen::Isometry3d> start_pose;
  std::optional<Pose3Dof> initial_prior;
  bool robot = false;
  std::unique_ptr<GroundTruth> ground_truth;
  std::unique_ptr<VideoSource> source;
  Frame first;
  double fps = 30.0;
};

ReplaySetup Prepare(const ReplayOptions& opt) {
  ReplaySetup s;
  const bool has_prior = !opt.prior.empty();
  if (has_prior && !opt.prior_file.empty()) {
    throw InputError("replay: give either --prior-file or --prior, not both");
  }
  const bool has_height_tilt = opt.has_height || opt.has_tilt;
  if ((has_prior || has_height_tilt) && !(opt.has_height && opt.has_tilt)) {
    throw InputError(has_prior ? "replay: --prior needs both --height and --tilt"
                               : "replay: --height and --tilt go together");
  }
  if (!has_prior && opt.prior_file.empty() && opt.init_pose.empty()) {
    throw InputError("replay: nothing to start from: give --init-pose, --prior-file or --prior");
  }
  if (has_height_tilt) {
    CheckHeight(opt.height, "--height");
    CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  }
  CheckRange(opt.delta_t, 0.0, 100.0, "--delta-t");
  CheckRange(opt.delta_phi_deg, 0.1, 180.0, "--delta-phi");
  CheckRange(opt.fps, 0.0, 10000.0, "--fps");
  if (opt.max_frames < 0) throw InputError("--frames: must be >= 0");
  if (has_prior) s.initial_prior = ParsePrior(opt.prior, "--prior");
  s.robot = has_prior || has_height_tilt || !opt.prior_file.empty();

  s.camera = LoadCamera(opt.camera);
  TrackerSettings base;
  base.visibility.scanline = opt.scanline;
  s.settings = opt.settings.empty() ? base : ReadTrackerSettings(opt.settings, base);
  if (!opt.prior_file.empty()) s.priors = ReadPriors(opt.prior_file);
  if (!opt.init_pose.empty()) s.start_pose = ReadPoseFile(opt.init_pose);
  s.ground_truth = std::make_unique<GroundTruth>(opt.ground_truth);

  // Frame rate: --fps, else the video's own, else the step of the prior or ground-truth times.
  SequencePattern pattern;
  const bool sequence = ParseSequencePattern(opt.input, &pattern);
  VideoSourceOptions source_options;
  source_options.frame_rate = opt.fps;
  if (opt.fps <= 0.0 && sequence) {
    std::vector<double> times;
    for (const PriorRecord& r : s.priors)
      times.push_back(r.t);
    if (times.size() < 2) times = s.ground_truth->Times();
    const double step = MedianTimeStep(times);
    if (step > 0.0) source_options.frame_rate = 1.0 / step;
  }
  s.source = std::make_unique<VideoSource>(opt.input, source_options);
  if (s.source->Grab(&s.first) != FrameStatus::kOk) {
    throw InputError(opt.input + ": no frame can be read");
  }
  const int width = static_cast<int>(s.first.image.getWidth());
  const int height = static_cast<int>(s.first.image.getHeight());
  if (s.camera.width <= 0) {
    s.camera.width = width;
    s.camera.height = height;
  } else if (s.camera.width != width || s.camera.height != height) {
    throw InputError(opt.camera + ": the camera is " + std::to_string(s.camera.width) + "x" +
                     std::to_string(s.camera.height) + ", the frames of " + opt.input + " are " +
                     std::to_string(width) + "x" + std::to_string(height));
  }
  s.fps = source_options.frame_rate > 0.0 ? source_options.frame_rate : 30.0;
  return s;
}

std::optional<RobotReading> ReadingAt(const ReplayOptions& opt, const ReplaySetup& s, double t) {
  if (!s.robot) return std::nullopt;
  RobotReading reading;
  if (!s.priors.empty()) {
    const std::optional<RobotPose> prior = InterpolatePrior(s.priors, t, 1.0 / s.fps + 0.5);
    if (!prior) return std::nullopt;  // outside the prior file: a free frame
    reading.odometry = prior->Planar();
    reading.height = prior->height;
    reading.tilt = prior->tilt;
    return reading;
  }
  reading.height = opt.height;
  reading.tilt = DegToRad(opt.tilt_deg);
  return reading;
}

// Prints a progress bar on stderr when it is a terminal, at most ten times a second.
class Progress {
 public:
  Progress(long total, bool enabled) : total_(total), enabled_(enabled && isatty(STDERR_FILENO)) {}
  void Update(long done, int tracked, bool force = false) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double seconds = std::chrono::duration<double>(now - start_).count();
    std::string bar;
    if (total_ > 0) {
      const int filled = static_cast<int>(30.0 * done / total_);
      bar = "[" + std::string(filled, '#') + std::string(30 - filled, ' ') + "] ";
    }
    std::fprintf(stderr, "\r%s%ld%s frames, %.0f frames/s, %d with a pose   ", bar.c_str(), done,
                 total_ > 0 ? ("/" + std::to_string(total_)).c_str() : "",
                 seconds > 0 ? done / seconds : 0.0, tracked);
    if (force) std::fprintf(stderr, "\n");
  }

 private:
  long total_;
  bool enabled_;
  Clock::time_point start_ = Clock::now(), last_;
};

// The localiser, tracker and model of one replay, built before any output is written.
class ReplayTracking {
 public:
  ReplayTracking(const ReplayOptions& opt, const ReplaySetup& s)
      : camera_(s.camera),
        loaded_(cache_.Model(opt.model)),
        tracker_(opt.model, s.camera, s.settings) {
    if (s.robot) {
      LocalizerOptions matcher;
      matcher.noise = DetectedLineNoise();  // lines from LineExtractor
      localizer_ = std::make_unique<Localizer>(*loaded_.model, loaded_.regions.get(),
                                               loaded_.area.get(), s.camera, matcher);
      RelocalizationOptions relocalization;
      relocalization.initial = SearchBounds{opt.delta_t, DegToRad(opt.delta_phi_deg)};
      // The tracker hands undistorted frames over: segments stay in their pixels (no camera).
      relocalizer_ = std::make_unique<Relocalizer>(
          *localizer_, MakeLineExtractorFunction(opt.lines.Options()), relocalization);
    }
    sequence_ = std::make_unique<SequenceTracker>(&tracker_, s.camera, relocalizer_.get(),
                                                  SequenceTrackerOptions());
    if (s.start_pose) sequence_->SetStartPose(*s.start_pose);
    if (s.initial_prior) sequence_->SetInitialPrior(*s.initial_prior);
    occlusion_ = std::make_unique<OcclusionTester>(*loaded_.model);
  }

  SequenceTracker& sequence() { return *sequence_; }

  // The model edges visible at `cam_from_world`, in pixels of the undistorted frame.
  std::vector<Segment2> VisibleEdges(const Eigen::Isometry3d& cam_from_world) const {
    std::vector<Segment2> edges;
    for (const ProjectedEdge& e :
         ProjectVisibleEdges(*loaded_.model, *occlusion_, cam_from_world, camera_.Undistorted())) {
      edges.push_back(e.image);
    }
    return edges;
  }

 private:
  CameraIntrinsics camera_;
  LocalizerCache cache_{LocalizerOptions()};
  const LoadedModel& loaded_;
  EdgeTracker tracker_;
  std::unique_ptr<Localizer> localizer_;
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<SequenceTracker> sequence_;
  std::unique_ptr<OcclusionTester> occlusion_;
};

// The state of a replay's outputs as the frames go by.
struct ReplayRun {
  // Creates the log and the overlay in opt.out, which must exist.
  ReplayRun(const ReplayOptions& opt, const ReplaySetup& s)
      : out(opt.out), log(opt.out, s.ground_truth->enabled()) {
    if (!opt.no_overlay) {
      overlay = std::make_unique<OverlayWriter>(opt.out, opt.overlay_png, s.fps,
                                                cv::Size(s.camera.width, s.camera.height));
    }
    info.input = opt.input;
    info.model = opt.model;
    info.camera = opt.camera;
    info.settings = s.settings.source;
    info.overlay_path = overlay ? overlay->path() : "";
    info.overlay_codec = overlay ? overlay->codec() : "";
  }

  std::string out;
  ReplayLog log;
  std::unique_ptr<OverlayWriter> overlay;
  ReplayRunInfo info;
  std::vector<ReplayFrameRecord> records;
  int with_pose = 0;
  double overlay_ms = 0.0;
  double decode_ms = 0.0;  // reading the frame being processed
  Clock::time_point start = Clock::now(), last_summary = start;
};

// Writes summary.json as the run stands (atomically: a reader never sees a partial file).
void WriteSummary(const SequenceTracker& sequence, ReplayRun* run) {
  run->info.losses = sequence.losses();
  run->info.recoveries = sequence.recoveries();
  WriteFileAtomically(run->out + "/summary.json",
                      ReplaySummary(run->records, run->info).dump(2) + "\n");
}

// What the log and the summary keep of one processed frame; errors against the ground truth
// when it has the frame.
ReplayFrameRecord RecordFrame(const Frame& frame, const FrameReport& report, const ReplaySetup& s) {
  ReplayFrameRecord record;
  record.frame = static_cast<long>(frame.frame_id);
  record.t = frame.timestamp_s;
  record.status = report.status;
  record.has_pose = report.cam_from_world.has_value();
  record.projection_error_deg = report.health.projection_error_deg;
  record.edges_good = report.health.edges_good;
  if (report.cam_from_world) {
    if (const auto truth = s.ground_truth->At(record.frame, record.t, 0.5 / s.fps)) {
      const PoseDifference d = ComparePoses(*report.cam_from_world, *truth);
      record.translation_error_m = d.translation;
      record.rotation_error_deg = RadToDeg(d.rotation);
    }
  }
  return record;
}

// Processes one frame: tracks it, logs it and draws its overlay.
void ProcessFrame(const ReplayOptions& opt, const ReplaySetup& s, const Frame& frame,
                  ReplayTracking* tracking, ReplayRun* run) {
  SequenceTracker& sequence = tracking->sequence();
  const Clock::time_point step_start = Clock::now();
  const std::optional<RobotReading> reading = ReadingAt(opt, s, frame.timestamp_s);
  const FrameReport report = sequence.Process(frame.image, frame.timestamp_s, reading);
  ReplayFrameRecord record = RecordFrame(frame, report, s);
  record.step_ms = Milliseconds(Clock::now() - step_start);
  record.decode_ms = run->decode_ms;
  run->with_pose += record.has_pose ? 1 : 0;
  run->log.Add(record, report);
  run->records.push_back(record);
  if (!run->overlay) return;
  const Clock::time_point overlay_start = Clock::now();
  const std::vector<Segment2> edges = report.cam_from_world
                                          ? tracking->VisibleEdges(*report.cam_from_world)
                                          : std::vector<Segment2>();
  run->overlay->Add(DrawOverlay(sequence.undistorted(), edges, report, record.frame, record.t),
                    record.frame);
  run->overlay_ms += Milliseconds(Clock::now() - overlay_start);
}

// Grabs the next frame into *frame; false when the run ends here (the reason in run->info).
bool GrabNext(const ReplayOptions& opt, const ReplaySetup& s, Frame* frame, ReplayRun* run) {
  if (StopSignals::Received() != 0) {
    run->info.interruption = StopSignals::ReceivedName();
    return false;
  }
  if (opt.max_frames > 0 && static_cast<long>(run->records.size()) >= opt.max_frames) {
    run->info.complete = true;
    return false;
  }
  const Clock::time_point grab_start = Clock::now();
  FrameStatus status;
  try {
    status = s.source->Grab(frame);
  } catch (const InputError& e) {
    run->info.interruption = std::string("the source failed: ") + e.what();
    return false;
  }
  run->decode_ms = Milliseconds(Clock::now() - grab_start);
  if (status == FrameStatus::kEndOfStream) {
    run->info.complete = true;
    return false;
  }
  if (status != FrameStatus::kOk) {
    run->info.interruption = std::string("the source stopped: ") + ToString(status);
    return false;
  }
  return true;
}

// Closes the overlay, writes the error plot and the final summary.
void FinishFiles(const SequenceTracker& sequence, ReplayRun* run) {
  if (run->overlay) run->overlay->Close();
  run->info.wall_s = Milliseconds(Clock::now() - run->start) / 1000.0;
  if (run->info.complete) run->info.interruption.clear();
  if (const std::optional<cv::Mat> plot = DrawErrorPlot(run->records)) {
    run->info.error_plot = "error_plot.png";
    std::vector<unsigned char> png;
    cv::imencode(".png", *plot, png);
    WriteFileAtomically(run->out + "/error_plot.png", std::string(png.begin(), png.end()));
  }
  WriteSummary(sequence, run);
}

// The one line on stdout: frames, poses, losses, throughput and, with ground truth, the errors.
void PrintReplayLine(const SequenceTracker& sequence, const ReplayRun& run) {
  const nlohmann::ordered_json summary = ReplaySummary(run.records, run.info);
  std::cout << "replayed " << run.records.size() << " frames: " << run.with_pose << " with a pose ("
            << summary["status_counts"].dump() << "), " << sequence.losses() << " losses, "
            << sequence.recoveries() << " recoveries, "
            << static_cast<int>(summary["throughput_fps"].get<double>())
            << " frames/s without the overlay";
  if (summary.contains("ground_truth")) {
    std::cout << std::fixed << std::setprecision(2) << "; ATE "
              << summary["ground_truth"]["ate_rmse_m"].get<double>() * 100.0 << " cm, worst "
              << summary["ground_truth"]["translation_m"]["max"].get<double>() * 100.0 << " cm / "
              << summary["ground_truth"]["rotation_deg"]["max"].get<double>() << " deg";
  }
  std::cout << (run.info.complete ? "" : " (interrupted: " + run.info.interruption + ")")
            << std::endl;
}

int RunReplay(const ReplayOptions& opt) {
  ReplaySetup s = Prepare(opt);
  ReplayTracking tracking(opt, s);
  // Everything is valid: the outputs appear from here on, frame by frame.
  EnsureDirectory(opt.out);
  ReplayRun run(opt, s);
  StopSignals signals;
  Progress progress(opt.max_frames > 0 ? opt.max_frames : s.source->FrameCount(),
                    spdlog::get_level() <= spdlog::level::info);
  run.info.interruption = "still running (a summary of a replay that stopped without finishing)";
  WriteSummary(tracking.sequence(), &run);
  Frame frame = std::move(s.first);
  do {
    ProcessFrame(opt, s, frame, &tracking, &run);
    progress.Update(static_cast<long>(run.records.size()), run.with_pose);
    run.info.wall_s = Milliseconds(Clock::now() - run.start) / 1000.0;
    run.info.overlay_s = run.overlay_ms / 1000.0;
    if (Clock::now() - run.last_summary > std::chrono::seconds(2)) {
      WriteSummary(tracking.sequence(), &run);
      run.last_summary = Clock::now();
    }
  } while (GrabNext(opt, s, &frame, &run));
  progress.Update(static_cast<long>(run.records.size()), run.with_pose, true);
  FinishFiles(tracking.sequence(), &run);
  PrintReplayLine(tracking.sequence(), run);
  return run.info.complete && run.with_pose > 0 ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddReplay(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<ReplayOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "replay",
      "Track a recorded video or image sequence: started by the matcher from a robot prior (or "
      "from a ViSP pose file), recovered after losses; poses, per-frame log, overlay, summary");
  cmd->add_option("--input", opt->input, "Video file or printf image pattern 'DIR/frame_%05d.png'")
      ->required();
  cmd->add_option("--model", opt->model, "ViSP .cao model")->required();
  cmd->add_option("--camera", opt->camera,
                  "Camera file: ViSP XML, OpenCV or ROS YAML (its distortion is undone)")
      ->required();
  cmd->add_option("--out", opt->out, "Output folder")->required();
  cmd->add_option("--prior-file", opt->prior_file,
                  "Robot readings per time: CSV t,x,y,heading_deg,height,tilt_deg");
  cmd->add_option("--prior", opt->prior,
                  "Robot start prior X,Y,HEADING_DEG (with --height, --tilt)");
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)");
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt below the horizontal (degrees)");
  cmd->add_option("--delta-t", opt->delta_t, "Position bound of the first prior (metres)")
      ->capture_default_str();
  cmd->add_option("--delta-phi", opt->delta_phi_deg, "Heading bound of the first prior (degrees)")
      ->capture_default_str();
  cmd->add_option("--init-pose", opt->init_pose,
                  "Start pose cMo: ViSP .0.pos (tx ty tz tux tuy tuz) or a 4x4 matrix file");
  cmd->add_option("--settings", opt->settings, "ViSP tracker XML (<ecm>, <face>)");
  cmd->add_option("--ground-truth", opt->ground_truth,
                  "TUM trajectory (camera in world), or a printf pattern of ViSP cMo pose files "
                  "numbered like the frames");
  cmd->add_option(
      "--fps", opt->fps,
      "Frame rate (default: the video's, else the prior or ground-truth time step, else "
      "30)");
  cmd->add_option("--frames", opt->max_frames, "Stop after this many frames (0: all)");
  cmd->add_flag("--overlay-png", opt->overlay_png, "Overlay as DIR/overlay/frame_%05d.png");
  cmd->add_flag("--no-overlay", opt->no_overlay, "No overlay");
  AddLineFlags(cmd, &opt->lines, /*with_camera=*/false);
  cmd->add_flag("--scanline", opt->scanline,
                "Scan-line visibility (hidden edge parts not tracked; about 4x slower)");
  cmd->callback([opt, action, cmd] {
    opt->has_height = cmd->count("--height") > 0;
    opt->has_tilt = cmd->count("--tilt") > 0;
    const bool robot = opt->has_height || opt->has_tilt || cmd->count("--prior") > 0 ||
                       cmd->count("--prior-file") > 0;
    RefuseUnless(*cmd, cmd->count("--prior-file") == 0, {"--height", "--tilt"},
                 "not with --prior-file (it gives each frame's height and tilt)");
    RefuseUnless(*cmd, robot,
                 {"--delta-t", "--delta-phi", "--detector", "--min-length", "--roi", "--no-merge",
                  "--undistort"},
                 "applies to the matcher, which needs a robot's readings (--prior-file, or "
                 "--prior with --height and --tilt)");
    RefuseUnless(*cmd, !opt->no_overlay, {"--overlay-png"}, "not with --no-overlay");
    *action = [opt] { return RunReplay(*opt); };
  });
}

}  // namespace linetrack::app

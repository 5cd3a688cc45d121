// `linetrack replay`: tracks a recorded video or image sequence against a .cao model, started by
// the matcher from a robot prior (or from a ViSP pose file), and writes DIR/poses.txt (TUM),
// DIR/frames.csv, DIR/overlay.mp4 (or PNG frames), DIR/summary.json and, with ground truth,
// DIR/error_plot.png. Files are written frame by frame; SIGINT/SIGTERM stop cleanly.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "app/commands.h"
#include "app/global_mode_flags.h"
#include "app/ground_truth.h"
#include "app/head_mount.h"
#include "app/integrity_output.h"
#include "app/line_flags.h"
#include "app/localize_image.h"
#include "app/localize_io.h"
#include "app/progress_bar.h"
#include "app/recording.h"
#include "app/replay_output.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/occlusion.h"
#include "tracking/capture/video_source.h"
#include "tracking/tracker/pose_file.h"
#include "tracking/tracker/robot_readings.h"
#include "tracking/tracker/tracking_engine.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

struct ReplayOptions {
  std::string input, model, camera, prior_file, prior, init_pose, settings, ground_truth, out;
  std::string mount;  // calibrated camera mount: the prior's tilt is the head's
  double height = 0.0, tilt_deg = 0.0;
  bool has_height = false, has_tilt = false;  // --height, --tilt given
  double delta_t = SearchBounds().delta_t;
  double delta_phi_deg = RadToDeg(SearchBounds().delta_phi);
  double fps = 0.0;
  double time_offset = 0.0;  // seconds added to the frames' times to read priors, ground truth
  bool align_times = false;  // time_offset = first prior (or ground-truth) time - first frame's
  long max_frames = 0;
  bool overlay_png = false, no_overlay = false, scanline = false;
  LineFlags lines;             // the line extractor of the re-localisation
  IntegrityFlags integrity;    // the alert limit and the sigmas of the pose integrity
  CoastFlags coast;            // the odometry's bound and the coasting limits
  GlobalModeFlags global;      // when a lost robot switches to the global mode
  RecordingOptions recording;  // a rosbag input (--image-topic ...)
  RecordingOpener open_recording;
};

bool IsRecording(const std::string& input) {
  return input.size() > 4 && input.compare(input.size() - 4, 4, ".bag") == 0;
}

double Milliseconds(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// Everything a replay needs, read and checked before any output is written.
struct ReplaySetup {
  CameraIntrinsics camera;
  TrackerSettings settings;
  std::vector<PriorRecord> priors;
  std::optional<Eigen::Isometry3d> start_pose;
  std::optional<Pose3Dof> initial_prior;
  bool robot = false;
  std::optional<BelievedHead> head;  // --mount
  std::unique_ptr<GroundTruth> ground_truth;
  std::unique_ptr<VideoSource> video;
  std::unique_ptr<Recording> recording;
  FrameSource* source = nullptr;  // the video's or the recording's frames
  long frame_count = 0;
  Frame first;
  double fps = 30.0;
  double time_offset = 0.0;  // --time-offset or --align-times
};

TrackerSettings ReadSettings(const ReplayOptions& opt) {
  TrackerSettings base;
  base.visibility.scanline = opt.scanline;
  return opt.settings.empty() ? base : ReadTrackerSettings(opt.settings, base);
}

// Reads the first frame; the camera takes its size, or must have it.
void GrabFirstFrame(const ReplayOptions& opt, ReplaySetup* s) {
  if (s->source->Grab(&s->first) != FrameStatus::kOk) {
    throw InputError(opt.input + ": no frame can be read");
  }
  const int width = static_cast<int>(s->first.image.getWidth());
  const int height = static_cast<int>(s->first.image.getHeight());
  if (s->camera.width <= 0) {
    s->camera.width = width;
    s->camera.height = height;
  } else if (s->camera.width != width || s->camera.height != height) {
    throw InputError((opt.camera.empty() ? opt.input : opt.camera) + ": the camera is " +
                     std::to_string(s->camera.width) + "x" + std::to_string(s->camera.height) +
                     ", the frames of " + opt.input + " are " + std::to_string(width) + "x" +
                     std::to_string(height));
  }
}

// A recording (rosbag): its odometry is the prior file, --prior moves it to the map.
void PrepareRecording(const ReplayOptions& opt, ReplaySetup* s) {
  if (!opt.open_recording) throw InputError(opt.input + ": this build cannot read rosbag files");
  if (!opt.prior_file.empty()) throw InputError("replay: a bag's odometry replaces --prior-file");
  if (opt.recording.image_topic.empty()) throw InputError("replay: a bag needs --image-topic");
  if (!opt.mount.empty()) {
    if (opt.recording.joint_states_topic.empty() || opt.recording.odom_topic.empty()) {
      throw InputError("replay: --mount with a bag needs --joint-states-topic and --odom-topic");
    }
  } else if (!opt.has_height) {
    throw InputError("replay: a bag needs --height");
  }
  if (opt.has_height) CheckHeight(opt.height, "--height");
  if (opt.has_tilt) CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  if (!opt.has_tilt && opt.recording.joint_states_topic.empty()) {
    throw InputError("replay: a bag needs --tilt or --joint-states-topic");
  }
  RecordingOptions options = opt.recording;
  options.height = opt.height;
  options.tilt = opt.has_tilt ? DegToRad(opt.tilt_deg) : 0.0;
  if (!opt.mount.empty()) {
    options.head = BelieveHead(HeadModel::kPtu46, ReadMountFile(opt.mount), opt.mount,
                               opt.has_height ? std::optional<double>(opt.height) : std::nullopt);
  }
  if (!opt.prior.empty()) options.start = ParsePrior(opt.prior, "--prior");
  s->recording = opt.open_recording(opt.input, options);
  s->priors = s->recording->priors();
  s->robot = true;
  if (s->priors.empty()) {  // no odometry: --prior starts it, the fixed tilt holds
    if (opt.prior.empty()) throw InputError("replay: a bag without --odom-topic needs --prior");
    if (!opt.has_tilt) throw InputError("replay: a bag without odometry needs --tilt");
    s->initial_prior = ParsePrior(opt.prior, "--prior");
  }
  if (opt.camera.empty()) {
    if (!s->recording->camera()) throw InputError("replay: give --camera or --camera-info-topic");
    s->camera = *s->recording->camera();
  } else {
    s->camera = LoadCamera(opt.camera);
  }
  s->source = &s->recording->frames();
  s->frame_count = s->recording->FrameCount();
  s->fps = s->recording->FrameRate();
}

// The offset between the frames' times and those of the prior file and ground truth (given, or
// aligning the first stamps), then a check that they overlap (one line, exit 2, when not).
void AlignTimes(const ReplayOptions& opt, long frames, ReplaySetup* s) {
  std::vector<double> prior_times;
  for (const PriorRecord& r : s->priors)
    prior_times.push_back(r.t);
  const std::vector<double> truth_times = s->ground_truth->Times();
  const double first = s->first.timestamp_s;
  s->time_offset = opt.time_offset;
  if (opt.align_times && opt.time_offset != 0.0) {
    throw InputError("replay: give either --time-offset or --align-times, not both");
  }
  if (opt.align_times) {
    const std::vector<double>& times = prior_times.empty() ? truth_times : prior_times;
    if (times.empty()) throw InputError("--align-times: no prior file or ground-truth times");
    s->time_offset = *std::min_element(times.begin(), times.end()) - first;
  }
  // Frame times from the first to the last frame read (all of them when the count is unknown).
  const long count =
      opt.max_frames > 0 && (frames <= 0 || opt.max_frames < frames) ? opt.max_frames : frames;
  const double last =
      count > 0 ? first + (count - 1) / s->fps : std::numeric_limits<double>::infinity();
  auto shifted = [&](std::vector<double> times) {
    for (double& t : times)
      t -= s->time_offset;
    return times;
  };
  const double tolerance = 1.0 / s->fps + 0.5;
  CheckTimesOverlap(
      shifted(prior_times), first, last, tolerance,
      s->recording ? opt.input + ": the odometry" : opt.prior_file + ": --prior-file");
  CheckTimesOverlap(shifted(truth_times), first, last, tolerance,
                    opt.ground_truth + ": --ground-truth");
}

ReplaySetup Prepare(const ReplayOptions& opt) {
  ReplaySetup s;
  if (IsRecording(opt.input)) {
    PrepareRecording(opt, &s);
    s.settings = ReadSettings(opt);
    s.ground_truth = std::make_unique<GroundTruth>(opt.ground_truth);
    GrabFirstFrame(opt, &s);
    AlignTimes(opt, s.frame_count, &s);
    return s;
  }
  if (opt.camera.empty()) throw InputError("replay: --camera is required");
  const bool has_prior = !opt.prior.empty();
  if (has_prior && !opt.prior_file.empty()) {
    throw InputError("replay: give either --prior-file or --prior, not both");
  }
  const bool has_height_tilt = opt.has_height || opt.has_tilt;
  const bool height_known = opt.has_height || !opt.mount.empty();  // or the mount's floor
  if ((has_prior || has_height_tilt) && !(height_known && opt.has_tilt)) {
    throw InputError(has_prior ? "replay: --prior needs both --height and --tilt"
                               : "replay: --height and --tilt go together");
  }
  if (!has_prior && opt.prior_file.empty() && opt.init_pose.empty()) {
    throw InputError("replay: nothing to start from: give --init-pose, --prior-file or --prior");
  }
  if (has_height_tilt) {
    if (opt.has_height || opt.mount.empty()) CheckHeight(opt.height, "--height");
    CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  }
  CheckRange(opt.delta_t, 0.0, 100.0, "--delta-t");
  CheckRange(opt.delta_phi_deg, 0.1, 180.0, "--delta-phi");
  CheckRange(opt.fps, 0.0, 10000.0, "--fps");
  if (opt.max_frames < 0) throw InputError("--frames: must be >= 0");
  opt.global.Options();  // the flags checked before any file is read
  if (has_prior) s.initial_prior = ParsePrior(opt.prior, "--prior");
  s.robot = has_prior || has_height_tilt || !opt.prior_file.empty();

  s.camera = LoadCamera(opt.camera);
  if (!opt.mount.empty()) {
    s.head = BelieveHead(HeadModel::kPtu46, ReadMountFile(opt.mount), opt.mount,
                         opt.has_height ? std::optional<double>(opt.height) : std::nullopt);
  }
  s.settings = ReadSettings(opt);
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
  s.video = std::make_unique<VideoSource>(opt.input, source_options);
  s.source = s.video.get();
  s.frame_count = s.video->FrameCount();
  GrabFirstFrame(opt, &s);
  s.fps = source_options.frame_rate > 0.0 ? source_options.frame_rate : 30.0;
  AlignTimes(opt, s.frame_count, &s);
  return s;
}

std::optional<RobotReading> ReadingAt(const ReplayOptions& opt, const ReplaySetup& s, double t) {
  if (!s.robot) return std::nullopt;
  RobotReading reading;
  if (!s.priors.empty()) {
    const std::optional<RobotPose> prior =
        InterpolatePrior(s.priors, t + s.time_offset, 1.0 / s.fps + 0.5);
    if (!prior) return std::nullopt;  // outside the prior file: a free frame
    reading.odometry = prior->Planar();
    reading.height = prior->height;
    reading.tilt = prior->tilt;
    reading.roll = prior->roll;
  } else {
    reading.height = opt.height;
    reading.tilt = DegToRad(opt.tilt_deg);
  }
  // With a calibrated mount the tilt is the head's: the camera's height and tilt follow.
  return s.head ? ReadingOnHead(*s.head, reading, reading.tilt) : reading;
}

// The localiser, tracker and model of one replay, built before any output is written.
class ReplayTracking {
 public:
  ReplayTracking(const ReplayOptions& opt, const ReplaySetup& s)
      : camera_(s.camera), loaded_(cache_.Model(opt.model)) {
    TrackingEngineOptions options;
    options.matcher.noise = DetectedLineNoise();  // lines from LineExtractor
    options.lines = opt.lines.Options();
    options.relocalization.initial = SearchBounds{opt.delta_t, DegToRad(opt.delta_phi_deg)};
    options.settings = s.settings;
    options.sequence.integrity = opt.integrity.Options();
    options.sequence.coast = opt.coast.Options();
    options.sequence.global = opt.global.Options();
    TrackingEngineModel model{opt.model, nullptr, nullptr, nullptr};
    if (s.robot) {
      model = {opt.model, loaded_.model.get(), loaded_.regions.get(), loaded_.area.get()};
    }
    engine_ = std::make_unique<TrackingEngine>(model, s.camera, options);
    if (s.start_pose) engine_->sequence().SetStartPose(*s.start_pose);
    if (s.initial_prior) engine_->sequence().SetInitialPrior(*s.initial_prior);
    occlusion_ = std::make_unique<OcclusionTester>(*loaded_.model);
  }

  SequenceTracker& sequence() { return engine_->sequence(); }

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
  std::unique_ptr<TrackingEngine> engine_;
  std::unique_ptr<OcclusionTester> occlusion_;
};

// The state of a replay's outputs as the frames go by.
struct ReplayRun {
  // Creates the log and the overlay in opt.out, which must exist.
  ReplayRun(const ReplayOptions& opt, const ReplaySetup& s)
      : out(opt.out),
        log(opt.out, s.ground_truth->enabled(), opt.integrity.all_poses),
        integrity_options(opt.integrity.Options()) {
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
  IntegrityOptions integrity_options;  // the alert limit and allowances of the run
  IntegrityTally integrity;            // statuses and sigmas; with ground truth the failures
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
  run->info.integrity = run->integrity.Summary(run->integrity_options);
  WriteFileAtomically(run->out + "/summary.json",
                      ReplaySummary(run->records, run->info).dump(2) + "\n");
}

// What the log and the summary keep of one processed frame; errors against the ground truth
// when it has the frame, and the pose's integrity (tallied into *integrity).
ReplayFrameRecord RecordFrame(const Frame& frame, const FrameReport& report, const ReplaySetup& s,
                              IntegrityTally* integrity) {
  ReplayFrameRecord record;
  record.frame = static_cast<long>(frame.frame_id);
  record.t = frame.timestamp_s;
  record.status = report.status;
  record.has_pose = report.cam_from_world.has_value();
  record.projection_error_deg = report.health.projection_error_deg;
  record.edges_good = report.health.edges_good;
  std::optional<IntegrityCheck> check;
  if (report.cam_from_world) {
    if (const auto truth =
            s.ground_truth->At(record.frame, record.t + s.time_offset, 0.5 / s.fps)) {
      const PoseDifference d = ComparePoses(*report.cam_from_world, *truth);
      record.translation_error_m = d.translation;
      record.rotation_error_deg = RadToDeg(d.rotation);
      check = CheckAgainstTruth(report.uncertainty, *report.cam_from_world, *truth, s.robot);
    }
  }
  integrity->Add(report.uncertainty, check);
  return record;
}

// Processes one frame: tracks it, logs it (and into the output bag) and draws its overlay.
void ProcessFrame(const ReplayOptions& opt, const ReplaySetup& s, const Frame& frame,
                  ReplayTracking* tracking, ReplayRun* run) {
  SequenceTracker& sequence = tracking->sequence();
  const Clock::time_point step_start = Clock::now();
  const std::optional<RobotReading> reading = ReadingAt(opt, s, frame.timestamp_s);
  const FrameReport report = sequence.Process(frame.image, frame.timestamp_s, reading);
  ReplayFrameRecord record = RecordFrame(frame, report, s, &run->integrity);
  record.step_ms = Milliseconds(Clock::now() - step_start);
  record.decode_ms = run->decode_ms;
  run->with_pose += record.has_pose ? 1 : 0;
  run->log.Add(record, report);
  if (s.recording) s.recording->Add(record.t, report);
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
            << summary["status_counts"].dump() << "; integrity "
            << summary["integrity"]["status_counts"].dump() << "), " << sequence.losses()
            << " losses, " << sequence.recoveries() << " recoveries, "
            << static_cast<int>(summary["throughput_fps"].get<double>())
            << " frames/s without the overlay";
  if (summary.contains("ground_truth")) {
    std::cout << std::fixed << std::setprecision(2) << "; ATE "
              << summary["ground_truth"]["ate_rmse_m"].get<double>() * 100.0 << " cm, worst "
              << summary["ground_truth"]["translation_m"]["max"].get<double>() * 100.0 << " cm / "
              << summary["ground_truth"]["rotation_deg"]["max"].get<double>() << " deg";
  }
  if (summary["integrity"].contains("ground_truth")) {
    std::cout << "; integrity failures "
              << summary["integrity"]["ground_truth"]["integrity_failures"].get<int>();
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
  Progress progress(opt.max_frames > 0 ? opt.max_frames : s.frame_count,
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
  if (s.recording) s.recording->Finish();
  FinishFiles(tracking.sequence(), &run);
  PrintReplayLine(tracking.sequence(), run);
  return run.info.complete && run.with_pose > 0 ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddReplay(CLI::App& cli, CommandAction* action) {
  AddReplayWithRecordings(cli, action, {});
}

void AddReplayWithRecordings(CLI::App& cli, CommandAction* action, RecordingOpener open_recording) {
  auto opt = std::make_shared<ReplayOptions>();
  opt->open_recording = std::move(open_recording);
  CLI::App* cmd = cli.add_subcommand(
      "replay",
      "Track a recorded video or image sequence: started by the matcher from a robot prior (or "
      "from a ViSP pose file), recovered after losses; poses, per-frame log, overlay, summary");
  cmd->add_option("--input", opt->input,
                  "Video file, printf image pattern 'DIR/frame_%05d.png' or rosbag file (.bag)")
      ->required();
  cmd->add_option("--model", opt->model, "ViSP .cao model")->required();
  cmd->add_option("--camera", opt->camera,
                  "Camera file: ViSP XML, OpenCV or ROS YAML (its distortion is undone); a "
                  "bag may give --camera-info-topic");
  cmd->add_option("--out", opt->out, "Output folder")->required();
  cmd->add_option("--prior-file", opt->prior_file,
                  "Robot readings per time: CSV t,x,y,heading_deg,height,tilt_deg");
  cmd->add_option("--prior", opt->prior,
                  "Robot start prior X,Y,HEADING_DEG (with --height, --tilt)");
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)");
  cmd->add_option("--tilt", opt->tilt_deg, "Camera tilt below the horizontal (degrees)");
  cmd->add_option("--mount", opt->mount,
                  "mount.json of linetrack calibrate-mount: --tilt and the prior file's tilt (a "
                  "bag's joint states) are the head's, the camera's height and tilt follow from "
                  "the mount (and its floor height, else --height taped with the head level)");
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
  cmd->add_option("--time-offset", opt->time_offset,
                  "Seconds added to the frames' times to read --prior-file and --ground-truth "
                  "(their time base minus the frames')")
      ->capture_default_str();
  cmd->add_flag("--align-times", opt->align_times,
                "Align the first time of --prior-file (else --ground-truth) on the first frame's");
  cmd->add_option("--frames", opt->max_frames, "Stop after this many frames (0: all)");
  cmd->add_flag("--overlay-png", opt->overlay_png, "Overlay as DIR/overlay/frame_%05d.png");
  cmd->add_flag("--no-overlay", opt->no_overlay, "No overlay");
  AddLineFlags(cmd, &opt->lines, /*with_camera=*/false);
  AddIntegrityFlags(cmd, &opt->integrity);
  AddGlobalModeFlags(cmd, &opt->global);
  AddAllPosesFlag(cmd, &opt->integrity);
  AddCoastFlags(cmd, &opt->coast);
  RecordingOptions& bag = opt->recording;
  cmd->add_option("--image-topic", bag.image_topic, "Bag: sensor_msgs/Image topic");
  cmd->add_option("--odom-topic", bag.odom_topic, "Bag: nav_msgs/Odometry topic (the prior)");
  cmd->add_option("--camera-info-topic", bag.camera_info_topic,
                  "Bag: sensor_msgs/CameraInfo topic (instead of --camera)");
  cmd->add_option("--joint-states-topic", bag.joint_states_topic,
                  "Bag: sensor_msgs/JointState topic of the pan-tilt head");
  cmd->add_option("--pan-joint", bag.pan_joint, "Bag: the pan joint's name")->capture_default_str();
  cmd->add_option("--tilt-joint", bag.tilt_joint, "Bag: the tilt joint's name")
      ->capture_default_str();
  cmd->add_option("--out-bag", bag.out_bag,
                  "Bag: write the poses (PoseWithCovarianceStamped) and map -> odom (TF) here");
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
    RefuseUnless(*cmd, IsRecording(opt->input),
                 {"--image-topic", "--odom-topic", "--camera-info-topic", "--joint-states-topic",
                  "--pan-joint", "--tilt-joint", "--out-bag"},
                 "applies to a rosbag input (--input RUN.bag)");
    RefuseUnless(*cmd, !IsRecording(opt->input), {"--time-offset", "--align-times"},
                 "not with a rosbag input (its odometry has the images' stamps)");
    *action = [opt] { return RunReplay(*opt); };
  });
}

}  // namespace linetrack::app

// `linetrack replay`: tracks a recorded video or image sequence against a .cao model, started by
// the matcher from a robot prior (or from a ViSP pose file), and writes DIR/poses.txt (TUM),
// DIR/frames.csv, DIR/overlay.mp4 (or PNG frames), DIR/summary.json and, with ground truth,
// DIR/error_plot.png. Files are written frame by frame; SIGINT/SIGTERM stop cleanly.
#include <spdlog/spdlog.h>
#include <unistd.h>

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
#include "app/integrity_output.h"
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
  double height = std::nan(""), tilt_deg = std::nan("");
  double delta_t = SearchBounds().delta_t;
  double delta_phi_deg = RadToDeg(SearchBounds().delta_phi);
  double fps = 0.0;
  double time_offset = 0.0;  // seconds added to the frames' times to read priors, ground truth
  bool align_times = false;  // time_offset = first prior (or ground-truth) time - first frame's
  long max_frames = 0;
  bool overlay_png = false, no_overlay = false, scanline = false;
  LineFlags lines;  // the line extractor of the re-localisation
  IntegrityFlags integrity;
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
  double time_offset = 0.0;  // --time-offset or --align-times
};

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
  CheckTimesOverlap(shifted(prior_times), first, last, tolerance,
                    opt.prior_file + ": --prior-file");
  CheckTimesOverlap(shifted(truth_times), first, last, tolerance,
                    opt.ground_truth + ": --ground-truth");
}

ReplaySetup Prepare(const ReplayOptions& opt) {
  ReplaySetup s;
  const bool has_prior = !opt.prior.empty();
  if (has_prior && !opt.prior_file.empty()) {
    throw InputError("replay: give either --prior-file or --prior, not both");
  }
  const bool has_height_tilt = std::isfinite(opt.height) || std::isfinite(opt.tilt_deg);
  if ((has_prior || has_height_tilt) &&
      !(std::isfinite(opt.height) && std::isfinite(opt.tilt_deg))) {
    throw InputError("replay: --prior needs both --height and --tilt");
  }
  if (!has_prior && opt.prior_file.empty() && opt.init_pose.empty()) {
    throw InputError("replay: nothing to start from: give --init-pose, --prior-file or --prior");
  }
  if (has_height_tilt) {
    CheckRange(opt.height, 0.0, 100.0, "--height");
    CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  }
  CheckRange(opt.delta_t, 0.0, 100.0, "--delta-t");
  CheckRange(opt.delta_phi_deg, 0.1, 180.0, "--delta-phi");
  CheckRange(opt.fps, 0.0, 10000.0, "--fps");
  if (opt.max_frames < 0) throw InputError("--frames: must be >= 0");
  if (has_prior) s.initial_prior = ParsePrior(opt.prior, "--prior");
  s.robot = has_prior || has_height_tilt || !opt.prior_file.empty();

  s.camera = ReadCameraXml(opt.camera);
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
  AlignTimes(opt, s.source->FrameCount(), &s);
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

int RunReplay(const ReplayOptions& opt) {
  ReplaySetup s = Prepare(opt);
  LocalizerCache cache{LocalizerOptions()};
  const LoadedModel& loaded = cache.Model(opt.model);
  EdgeTracker tracker(opt.model, s.camera, s.settings);
  std::unique_ptr<Localizer> localizer;
  std::unique_ptr<Relocalizer> relocalizer;
  if (s.robot) {
    LocalizerOptions matcher;
    matcher.noise = DetectedLineNoise();  // lines from LineExtractor
    localizer = std::make_unique<Localizer>(*loaded.model, loaded.regions.get(), loaded.area.get(),
                                            s.camera, matcher);
    RelocalizationOptions relocalization;
    relocalization.initial = SearchBounds{opt.delta_t, DegToRad(opt.delta_phi_deg)};
    // The tracker hands undistorted frames over: segments stay in their pixels (no camera).
    relocalizer = std::make_unique<Relocalizer>(
        *localizer, MakeLineExtractorFunction(opt.lines.Options()), relocalization);
  }
  SequenceTrackerOptions sequence_options;
  sequence_options.integrity = opt.integrity.Options();
  SequenceTracker sequence(&tracker, s.camera, relocalizer.get(), sequence_options);
  if (s.start_pose) sequence.SetStartPose(*s.start_pose);
  if (s.initial_prior) sequence.SetInitialPrior(*s.initial_prior);
  const OcclusionTester occlusion(*loaded.model);

  // Everything is valid: the outputs appear from here on, frame by frame.
  EnsureDirectory(opt.out);
  ReplayLog log(opt.out, s.ground_truth->enabled(), opt.integrity.all_poses);
  IntegrityTally integrity;
  std::unique_ptr<OverlayWriter> overlay;
  if (!opt.no_overlay) {
    overlay = std::make_unique<OverlayWriter>(opt.out, opt.overlay_png, s.fps,
                                              cv::Size(s.camera.width, s.camera.height));
  }
  ReplayRunInfo info;
  info.input = opt.input;
  info.model = opt.model;
  info.camera = opt.camera;
  info.settings = s.settings.source;
  info.overlay_path = overlay ? overlay->path() : "";
  info.overlay_codec = overlay ? overlay->codec() : "";
  auto write_summary = [&](const std::vector<ReplayFrameRecord>& records) {
    info.losses = sequence.losses();
    info.recoveries = sequence.recoveries();
    info.integrity = integrity.Summary(sequence_options.integrity);
    WriteFileAtomically(opt.out + "/summary.json", ReplaySummary(records, info).dump(2) + "\n");
  };

  StopSignals signals;
  Progress progress(opt.max_frames > 0 ? opt.max_frames : s.source->FrameCount(),
                    spdlog::get_level() <= spdlog::level::info);
  std::vector<ReplayFrameRecord> records;
  int with_pose = 0;
  const Clock::time_point start = Clock::now();
  Clock::time_point last_summary = start;
  double overlay_ms = 0.0, decode_ms = 0.0;
  Frame frame = std::move(s.first);
  info.interruption = "still running (a summary of a replay that stopped without finishing)";
  write_summary(records);
  while (true) {
    const Clock::time_point step_start = Clock::now();
    const std::optional<RobotReading> reading = ReadingAt(opt, s, frame.timestamp_s);
    const FrameReport report = sequence.Process(frame.image, frame.timestamp_s, reading);
    ReplayFrameRecord record;
    record.frame = static_cast<long>(frame.frame_id);
    record.t = frame.timestamp_s;
    record.status = report.status;
    record.has_pose = report.cam_from_world.has_value();
    record.projection_error_deg = report.health.projection_error_deg;
    record.edges_good = report.health.edges_good;
    record.step_ms = Milliseconds(Clock::now() - step_start);
    record.decode_ms = decode_ms;
    std::optional<IntegrityCheck> check;
    if (report.cam_from_world) {
      ++with_pose;
      if (const auto truth =
              s.ground_truth->At(record.frame, record.t + s.time_offset, 0.5 / s.fps)) {
        const PoseDifference d = ComparePoses(*report.cam_from_world, *truth);
        record.translation_error_m = d.translation;
        record.rotation_error_deg = RadToDeg(d.rotation);
        check = CheckAgainstTruth(report.uncertainty, *report.cam_from_world, *truth, s.robot);
      }
    }
    integrity.Add(report.uncertainty, check);
    log.Add(record, report);
    records.push_back(record);
    if (overlay) {
      const Clock::time_point overlay_start = Clock::now();
      std::vector<Segment2> edges;
      if (report.cam_from_world) {
        for (const ProjectedEdge& e : ProjectVisibleEdges(
                 *loaded.model, occlusion, *report.cam_from_world, s.camera.Undistorted())) {
          edges.push_back(e.image);
        }
      }
      overlay->Add(DrawOverlay(sequence.undistorted(), edges, report, record.frame, record.t),
                   record.frame);
      overlay_ms += Milliseconds(Clock::now() - overlay_start);
    }
    progress.Update(static_cast<long>(records.size()), with_pose);
    info.wall_s = Milliseconds(Clock::now() - start) / 1000.0;
    info.overlay_s = overlay_ms / 1000.0;
    if (Clock::now() - last_summary > std::chrono::seconds(2)) {
      write_summary(records);
      last_summary = Clock::now();
    }
    if (StopSignals::Received() != 0) {
      info.interruption = StopSignals::ReceivedName();
      break;
    }
    if (opt.max_frames > 0 && static_cast<long>(records.size()) >= opt.max_frames) {
      info.complete = true;
      break;
    }
    const Clock::time_point grab_start = Clock::now();
    FrameStatus status;
    try {
      status = s.source->Grab(&frame);
    } catch (const InputError& e) {
      info.interruption = std::string("the source failed: ") + e.what();
      break;
    }
    decode_ms = Milliseconds(Clock::now() - grab_start);
    if (status == FrameStatus::kEndOfStream) {
      info.complete = true;
      break;
    }
    if (status != FrameStatus::kOk) {
      info.interruption = std::string("the source stopped: ") + ToString(status);
      break;
    }
  }
  progress.Update(static_cast<long>(records.size()), with_pose, true);
  if (overlay) overlay->Close();
  info.wall_s = Milliseconds(Clock::now() - start) / 1000.0;
  if (info.complete) info.interruption.clear();
  if (const std::optional<cv::Mat> plot = DrawErrorPlot(records)) {
    info.error_plot = "error_plot.png";
    std::vector<unsigned char> png;
    cv::imencode(".png", *plot, png);
    WriteFileAtomically(opt.out + "/error_plot.png", std::string(png.begin(), png.end()));
  }
  write_summary(records);
  const nlohmann::ordered_json summary = ReplaySummary(records, info);
  std::cout << "replayed " << records.size() << " frames: " << with_pose << " with a pose ("
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
  std::cout << (info.complete ? "" : " (interrupted: " + info.interruption + ")") << std::endl;
  return info.complete && with_pose > 0 ? kExitOk : kExitJobFailed;
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
  cmd->add_option("--camera", opt->camera, "ViSP camera XML (its distortion is undone)")
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
  AddAllPosesFlag(cmd, &opt->integrity);
  cmd->add_flag("--scanline", opt->scanline,
                "Scan-line visibility (hidden edge parts not tracked; about 4x slower)");
  cmd->callback([opt, action] { *action = [opt] { return RunReplay(*opt); }; });
}

}  // namespace linetrack::app

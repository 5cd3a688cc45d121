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
#include "app/head_mount.h"
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
  std::string mount;  // calibrated camera mount: the prior's tilt is the head's
  double height = std::nan(""), tilt_deg = std::nan("");
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
  std::optional<BelievedHead> head;  // --mount
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
  const bool has_height_tilt = std::isfinite(opt.height) || std::isfinite(opt.tilt_deg);
  const bool height_known = std::isfinite(opt.height) || !opt.mount.empty();  // or its floor
  if ((has_prior || has_height_tilt) && !(height_known && std::isfinite(opt.tilt_deg))) {
    throw InputError("replay: --prior needs both --height and --tilt");
  }
  if (!has_prior && opt.prior_file.empty() && opt.init_pose.empty()) {
    throw InputError("replay: nothing to start from: give --init-pose, --prior-file or --prior");
  }
  if (has_height_tilt) {
    if (std::isfinite(opt.height) || opt.mount.empty())
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
  if (!opt.mount.empty()) {
    s.head =
        BelieveHead(HeadModel::kPtu46, ReadMountFile(opt.mount), opt.mount,
                    std::isfinite(opt.height) ? std::optional<double>(opt.height) : std::nullopt);
  }
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
  } else {
    reading.height = opt.height;
    reading.tilt = DegToRad(opt.tilt_deg);
  }
  // With a calibrated mount the tilt is the head's: the camera's height and tilt follow.
  return s.head ? ReadingOnHead(*s.head, reading, reading.tilt) : reading;
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
  SequenceTracker sequence(&tracker, s.camera, relocalizer.get(), SequenceTrackerOptions());
  if (s.start_pose) sequence.SetStartPose(*s.start_pose);
  if (s.initial_prior) sequence.SetInitialPrior(*s.initial_prior);
  const OcclusionTester occlusion(*loaded.model);

  // Everything is valid: the outputs appear from here on, frame by frame.
  EnsureDirectory(opt.out);
  ReplayLog log(opt.out, s.ground_truth->enabled());
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
    if (report.cam_from_world) {
      ++with_pose;
      if (const auto truth = s.ground_truth->At(record.frame, record.t, 0.5 / s.fps)) {
        const PoseDifference d = ComparePoses(*report.cam_from_world, *truth);
        record.translation_error_m = d.translation;
        record.rotation_error_deg = RadToDeg(d.rotation);
      }
    }
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
  cmd->add_option("--mount", opt->mount,
                  "mount.json of linetrack calibrate-mount: --tilt and the prior file's tilt are "
                  "the head's, the camera's height and tilt follow from the mount (and its floor "
                  "height, else --height taped with the head level)");
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
  cmd->callback([opt, action] { *action = [opt] { return RunReplay(*opt); }; });
}

}  // namespace linetrack::app

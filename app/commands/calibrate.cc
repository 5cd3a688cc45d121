// `linetrack calibrate`: camera calibration from image files or a frame source (Zhang's method
// through ViSP, OpenCV's model beside it), and `linetrack bench calibrate` (its timing).
// docs/calibration.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/image_arguments.h"
#include "calibration/output_files.h"
#include "models/errors.h"
#include "models/statistics.h"
#include "tracking/capture/source_factory.h"

namespace linetrack::app {
namespace {

struct CalibrateCommandOptions {
  std::vector<std::string> images;  // files or glob patterns
  std::string source;               // frame source spec instead of files
  int frames = 20;                  // --source: views to collect
  int max_grabs = 2000;             // --source: frames to try at most
  std::string out_dir;
  std::string camera_name = "Camera";
  std::string pattern = "chessboard";
  CalibrationOptions calib;
  bool keep_all = false;
  int repeat = 5;  // bench only
};

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Frames from a source (camera, video, sequence) where the pattern is found, up to opt.frames.
std::vector<CalibrationImage> GrabViews(const CalibrateCommandOptions& opt) {
  std::unique_ptr<FrameSource> source = OpenFrameSource(opt.source, FrameSourceOptions());
  spdlog::info("grabbing from {}", source->Describe());
  std::vector<CalibrationImage> views;
  Frame frame;
  for (int grab = 0; grab < opt.max_grabs && static_cast<int>(views.size()) < opt.frames; ++grab) {
    const FrameStatus status = source->Grab(&frame);
    if (status == FrameStatus::kEndOfStream) break;
    if (status != FrameStatus::kOk) continue;
    const cv::Mat view(static_cast<int>(frame.image.getHeight()),
                       static_cast<int>(frame.image.getWidth()), CV_8U, frame.image.bitmap);
    if (!views.empty() && view.size() != views.front().gray.size()) {
      throw InputError(opt.source + ": the frame size changed while grabbing");
    }
    if (!DetectPattern(view, opt.calib.pattern, opt.calib.detection).found) continue;
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05lld.png", static_cast<long long>(frame.index));
    views.push_back({name, view.clone()});
    spdlog::info("view {}/{}: {}", views.size(), opt.frames, name);
  }
  if (views.empty()) {
    throw InputError(opt.source + ": the " + std::string(ToString(opt.calib.pattern.kind)) +
                     " pattern was found in no frame");
  }
  return views;
}

// Validates the options into opt->calib; throws InputError on bad usage.
void CheckOptions(CalibrateCommandOptions* opt) {
  const std::optional<PatternKind> kind = ParsePatternKind(opt->pattern);
  if (!kind) throw InputError("--pattern: expected chessboard, circles or charuco");
  opt->calib.pattern.kind = *kind;
  opt->calib.reject_outliers = !opt->keep_all;
  std::string why;
  if (!opt->calib.Check(&why)) throw InputError(why);
  if (opt->images.empty() == opt->source.empty()) {
    throw InputError("give either --images or --source");
  }
  if (opt->frames < 3) throw InputError("--frames: at least 3 views are needed");
}

void PrintResult(const CalibrationResult& r, double detect_s, double estimate_s) {
  std::cout << std::fixed << std::setprecision(3);
  std::cout << "view                 status              points  blur px  ViSP px  ViSP+d px  "
               "OpenCV px\n";
  for (const ViewReport& v : r.views) {
    char line[256];
    auto err = [](double e) { return e >= 0.0 ? e : std::numeric_limits<double>::quiet_NaN(); };
    std::snprintf(line, sizeof(line), "%-20s %-19s %6zu %8.2f %8.3f %10.3f %10.3f", v.name.c_str(),
                  ToString(v.status), v.detection.image_points.size(), v.detection.edge_blur_px,
                  err(v.error_visp_without), err(v.error_visp), err(v.error_opencv));
    std::cout << line << "\n";
  }
  for (const ViewReport& v : r.views) {
    if (v.status != ViewStatus::kUsed)
      std::cout << "rejected " << v.name << ": " << v.reason << "\n";
  }
  const CameraIntrinsics& a = r.visp.without;
  const CameraIntrinsics& b = r.visp.with;
  const CameraIntrinsics& f = r.visp.final_model;
  const VispCalibration& vi = r.visp;
  std::cout << "ViSP without distortion: px " << a.px << " py " << a.py << " u0 " << a.u0 << " v0 "
            << a.v0 << ", global error " << vi.global_error_without << " px\n";
  std::cout << std::setprecision(4) << "ViSP with distortion:    px " << b.px << " py " << b.py
            << " u0 " << b.u0 << " v0 " << b.v0 << " kud " << b.kud << " kdu " << b.kdu
            << ", global error " << vi.global_error_with << " px (ViSP's estimate)\n";
  std::cout << (vi.refined ? "refined (written):       px " : "written:                 px ")
            << f.px << " py " << f.py << " u0 " << f.u0 << " v0 " << f.v0 << " kud " << f.kud
            << " kdu " << f.kdu << ", RMS " << vi.rms_final << " px (std px " << vi.std_dev(0)
            << " py " << vi.std_dev(1) << " u0 " << vi.std_dev(2) << " v0 " << vi.std_dev(3)
            << " kud " << vi.std_dev(4) << ")\n";
  const OpenCvCalibration& o = r.opencv;
  std::cout << "OpenCV (flags " << o.flags << "):        fx " << o.fx << " fy " << o.fy << " cx "
            << o.cx << " cy " << o.cy << " k1 " << o.distortion[0] << " k2 " << o.distortion[1]
            << " p1 " << o.distortion[2] << " p2 " << o.distortion[3] << " k3 " << o.distortion[4]
            << ", RMS " << o.rms << " px\n";
  std::cout << std::setprecision(3) << r.UsedViews() << " of " << r.views.size()
            << " views used; detection " << detect_s << " s, estimation " << estimate_s << " s\n";
}

int RunCalibrate(CalibrateCommandOptions opt) {
  CheckOptions(&opt);
  if (opt.out_dir.empty()) throw InputError("--out is required");
  const std::vector<CalibrationImage> images =
      opt.source.empty() ? LoadCalibrationImages(ExpandImageArguments(opt.images)) : GrabViews(opt);
  auto start = std::chrono::steady_clock::now();
  const std::vector<PatternDetection> detections = DetectAll(images, opt.calib);
  const double detect_s = Seconds(start);
  std::vector<std::string> names;
  for (const CalibrationImage& image : images)
    names.push_back(image.name);
  start = std::chrono::steady_clock::now();
  const CalibrationResult result = CalibrateDetections(names, detections, images.front().gray.cols,
                                                       images.front().gray.rows, opt.calib);
  const double estimate_s = Seconds(start);
  switch (result.status) {
    case CalibrationStatus::kOk:
      break;
    case CalibrationStatus::kPatternNeverFound:
    case CalibrationStatus::kTooFewViews:
      throw InputError(result.message);
    case CalibrationStatus::kEstimationFailed:
      std::cerr << "linetrack: calibration failed: " << result.message << std::endl;
      return kExitJobFailed;
  }
  WriteOutputFolder(MakeCalibrationOutputs(result, images, opt.calib, opt.camera_name),
                    opt.out_dir);
  PrintResult(result, detect_s, estimate_s);
  std::cout << "wrote " << opt.out_dir
            << ": camera.xml opencv.yml camera_info.yaml report.json coverage.png overlays/\n";
  return kExitOk;
}

int RunBenchCalibrate(CalibrateCommandOptions opt) {
  if (opt.repeat < 1) throw InputError("--repeat: must be >= 1");
  CheckOptions(&opt);
  if (!opt.source.empty()) throw InputError("bench calibrate reads --images only");
  const std::vector<CalibrationImage> images =
      LoadCalibrationImages(ExpandImageArguments(opt.images));
  std::vector<double> detect, estimate, total;
  CalibrationResult result;
  for (int k = 0; k < opt.repeat; ++k) {
    auto start = std::chrono::steady_clock::now();
    const std::vector<PatternDetection> detections = DetectAll(images, opt.calib);
    detect.push_back(Seconds(start));
    std::vector<std::string> names;
    for (const CalibrationImage& image : images)
      names.push_back(image.name);
    auto mid = std::chrono::steady_clock::now();
    result = CalibrateDetections(names, detections, images.front().gray.cols,
                                 images.front().gray.rows, opt.calib);
    estimate.push_back(Seconds(mid));
    total.push_back(Seconds(start));
    if (!result.ok()) {
      std::cerr << "linetrack: calibration failed: " << result.message << std::endl;
      return kExitJobFailed;
    }
  }
  std::cout << std::fixed << std::setprecision(3) << "calibration of " << images.size()
            << " images (" << result.UsedViews() << " views used, " << opt.repeat
            << " runs, median): detection " << QuantileNearestRank(detect, 0.5) << " s, estimation "
            << QuantileNearestRank(estimate, 0.5) << " s, total " << QuantileNearestRank(total, 0.5)
            << " s\n";
  return kExitOk;
}

// Flags shared by `calibrate` and `bench calibrate`.
void AddCalibrationFlags(CLI::App* cmd, CalibrateCommandOptions* opt) {
  cmd->add_option("--images", opt->images,
                  "Image files or glob patterns (quote them: 'DIR/*.png'), sorted by name");
  cmd->add_option("--pattern", opt->pattern, "chessboard, circles or charuco")
      ->capture_default_str();
  cmd->add_option("--cols", opt->calib.pattern.cols, "Inner corners (or dots) per row")
      ->capture_default_str();
  cmd->add_option("--rows", opt->calib.pattern.rows, "Inner corners (or dots) per column")
      ->capture_default_str();
  cmd->add_option("--square", opt->calib.pattern.square, "Square size or dot spacing (metres)")
      ->capture_default_str();
  cmd->add_option("--marker", opt->calib.pattern.marker,
                  "ChArUco marker side (metres; default 0.7 x --square)");
  cmd->add_option("--dictionary", opt->calib.pattern.dictionary, "ChArUco ArUco dictionary")
      ->capture_default_str();
  cmd->add_flag("--sb", opt->calib.detection.chessboard_sb,
                "Chessboard corners by findChessboardCornersSB (default: findChessboardCorners + "
                "cornerSubPix 11x11, 30 iterations, eps 0.1)");
  cmd->add_option("--max-blur", opt->calib.detection.max_edge_blur_px,
                  "Views whose edge blur estimate (Gaussian sigma, px) exceeds this are rejected")
      ->capture_default_str();
  cmd->add_flag("--keep-all", opt->keep_all, "Do not reject outlier views");
  cmd->add_flag("!--no-refine", opt->calib.visp.refine,
                "Write ViSP's own distorted estimate (as its tutorial) instead of the refined one");
  cmd->add_option("--outlier-factor", opt->calib.outlier_factor,
                  "A view is an outlier when its RMS error exceeds this times the median")
      ->capture_default_str();
  cmd->add_option("--outlier-min-error", opt->calib.outlier_min_error_px,
                  "... and exceeds this many pixels")
      ->capture_default_str();
  cmd->add_flag("--fix-aspect-ratio", opt->calib.opencv.fix_aspect_ratio,
                "OpenCV model: fx = fy (CALIB_FIX_ASPECT_RATIO)");
  cmd->add_flag("--zero-tangent", opt->calib.opencv.zero_tangent,
                "OpenCV model: p1 = p2 = 0 (CALIB_ZERO_TANGENT_DIST)");
  cmd->add_flag("--fix-k3", opt->calib.opencv.fix_k3, "OpenCV model: k3 = 0 (CALIB_FIX_K3)");
}

// Refuses the pattern and rejection flags that the chosen pattern or --keep-all leave unused.
void RefuseUnusedCalibrationFlags(const CLI::App& cmd, const CalibrateCommandOptions& opt) {
  RefuseUnless(cmd, opt.pattern == "charuco", {"--marker", "--dictionary"},
               "applies to --pattern charuco");
  RefuseUnless(cmd, opt.pattern == "chessboard", {"--sb"}, "applies to --pattern chessboard");
  RefuseUnless(cmd, !opt.keep_all, {"--outlier-factor", "--outlier-min-error"},
               "not with --keep-all (no view is rejected as an outlier)");
}

}  // namespace

void AddCalibrate(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<CalibrateCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "calibrate",
      "Camera calibration (Zhang's method through ViSP, OpenCV's model too) from images of a "
      "chessboard, circle grid or ChArUco board; writes ViSP XML, OpenCV YAML, ROS camera_info, "
      "a JSON report, a coverage picture and per-view overlays into --out");
  AddCalibrationFlags(cmd, opt.get());
  cmd->add_option("--source", opt->source,
                  "Frame source instead of --images: aravis[:ID], v4l2[:/dev/videoN], a video "
                  "or an image sequence; frames showing the pattern become views");
  cmd->add_option("--frames", opt->frames, "--source: number of views to collect")
      ->capture_default_str();
  cmd->add_option("--max-grabs", opt->max_grabs, "--source: frames to try at most")
      ->capture_default_str();
  cmd->add_option("--out", opt->out_dir, "Output folder (written only when all succeeded)")
      ->required();
  cmd->add_option("--name", opt->camera_name, "Camera name in the XML and ROS files")
      ->capture_default_str();
  cmd->callback([opt, action, cmd] {
    RefuseUnusedCalibrationFlags(*cmd, *opt);
    RefuseUnless(*cmd, !opt->source.empty(), {"--frames", "--max-grabs"},
                 "applies to --source (frames grabbed until the pattern is seen)");
    *action = [opt] { return RunCalibrate(*opt); };
  });
}

void AddBenchCalibrate(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<CalibrateCommandOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "calibrate", "Time of a whole calibration (detection + estimation), median of --repeat runs");
  AddCalibrationFlags(cmd, opt.get());
  cmd->add_option("--repeat", opt->repeat, "Runs")->capture_default_str();
  cmd->callback([opt, action, cmd] {
    RefuseUnusedCalibrationFlags(*cmd, *opt);
    *action = [opt] { return RunBenchCalibrate(*opt); };
  });
}

}  // namespace linetrack::app

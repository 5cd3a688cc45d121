// `linetrack bench lines`: the line detectors side by side on 640x480 frames, one thread: time
// per frame, and on rendered hall views (ground truth from the renderer) how many visible model
// edges are found and how far the detected endpoints are.
#include <spdlog/spdlog.h>

#include <visp3/core/vpException.h>
#include <visp3/io/vpImageIo.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/image_overlay.h"
#include "app/model_loading.h"
#include "app/rendered_cases.h"
#include "matching/evaluation/line_evaluation.h"
#include "matching/lines/line_extractor.h"
#include "models/errors.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

// Visible model edges projecting at least this long must be found.
constexpr double kMinEdgeLengthPx = 40.0;

struct BenchLinesOptions {
  std::string model_path = "models/hall.cao";
  std::string visp_images = "/usr/share/visp-images-data/ViSP-images";
  int rendered = 50;    // rendered views per camera
  int max_frames = 60;  // frames taken (evenly spaced) from each ViSP sequence
  int repeat = 3;       // timed runs per frame
  int clutter = 10;
  uint64_t seed = 1;
  std::vector<std::string> detectors = {"hough", "lsd", "fld", "edlines"};
  std::string out_path;
  std::string dump_dir;  // overlays of the rendered views (default detector)
};

// A set of frames with, for rendered ones, the truth.
struct FrameSet {
  std::string name;
  std::optional<CameraIntrinsics> camera;  // undistortion (rendered sets)
  std::vector<vpImage<unsigned char>> images;
  std::vector<std::vector<ProjectedEdge>> truth;         // empty for real frames
  std::vector<std::vector<ObservablePiece>> observable;  // parts with contrast, not hidden
};

struct Figures {
  std::vector<double> ms;       // every timed run
  std::vector<double> best_ms;  // per frame, the fastest of its runs (least disturbed)
  std::vector<double> segments, endpoint_errors, offsets_px, angle_errors_deg;
  int edges = 0, found = 0;          // observable pieces >= kMinEdgeLengthPx
  int all_edges = 0, all_found = 0;  // visible pieces >= kMinEdgeLengthPx (geometry only)
};

double Rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v)
    sum += x * x;
  return v.empty() ? 0.0 : std::sqrt(sum / v.size());
}

CameraIntrinsics WideCamera() {
  CameraIntrinsics camera = PaperSyntheticCamera();
  camera.name = "wide";
  camera.px = camera.py = 500.0;
  camera.has_distortion = true;
  camera.kud = -0.08;
  camera.kdu = 0.085;
  return camera;
}

// The rendered views of a set: the benchmark's count, seed and clutter, seen by `camera`, each
// showing at most `max_edges` model edges.
RenderedCaseOptions SetOptions(const BenchLinesOptions& opt, const CameraIntrinsics& camera,
                               int max_edges) {
  RenderedCaseOptions options;
  options.count = opt.rendered;
  options.seed = opt.seed;
  options.camera = camera;
  options.clutter = opt.clutter;
  options.max_visible_edges = max_edges;
  return options;
}

FrameSet RenderedSet(const std::string& name, const RenderedCaseOptions& options,
                     const WireframeModel& model, const NavigableArea& area,
                     const OcclusionTester& occlusion) {
  FrameSet set{name, options.camera, {}, {}, {}};
  for (RenderedCase& c : RenderCases(model, area, occlusion, options)) {
    set.images.push_back(std::move(c.image));
    set.truth.push_back(std::move(c.truth));
    set.observable.push_back(std::move(c.observable));
  }
  return set;
}

// Up to `max_frames` frames of `files` (sorted), evenly spaced.
FrameSet ReadSet(const std::string& name, std::vector<std::string> files, int max_frames) {
  std::sort(files.begin(), files.end());
  FrameSet set{name, std::nullopt, {}, {}, {}};
  const size_t n = std::min(files.size(), static_cast<size_t>(max_frames));
  for (size_t k = 0; k < n; ++k) {
    const std::string& file = files[k * files.size() / n];
    vpImage<unsigned char> image;
    try {
      vpImageIo::read(image, file);
    } catch (const vpException& e) {
      throw InputError(file + ": cannot read the image (" + e.getMessage() + ")");
    }
    set.images.push_back(std::move(image));
  }
  return set;
}

std::vector<std::string> FilesWithExtension(const std::string& dir, const std::string& ext) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ext) files.push_back(entry.path().string());
  }
  return files;
}

// Overlay of a rendered view: detections red, model edges found green, missed blue.
void DumpOverlay(const std::string& path, const vpImage<unsigned char>& image,
                 const std::optional<CameraIntrinsics>& camera,
                 const std::vector<Segment2>& detections, const DetectionEvaluation& evaluation) {
  vpImage<vpRGBa> picture = ColourCopy(image);
  std::vector<Segment2> found, missed;
  for (const EdgeDetection& e : evaluation.edges)
    (e.found ? found : missed).push_back(e.edge);
  DrawSegments(&picture, found, vpColor::green, 3, camera);
  DrawSegments(&picture, missed, vpColor::blue, 3, camera);
  DrawSegments(&picture, detections, vpColor::red, 1, camera);
  WriteFileAtomically(path, EncodePngColour(picture));
}

Figures Measure(const FrameSet& set, const LineExtractionOptions& options, int repeat,
                const std::string& dump_dir = "") {
  LineExtractor extractor(options, set.camera);
  Figures figures;
  for (size_t f = 0; f < set.images.size(); ++f) {
    LineExtraction extraction;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repeat; ++r) {
      const auto start = std::chrono::steady_clock::now();
      extraction = extractor.Extract(set.images[f]);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      figures.ms.push_back(ms);
      best = std::min(best, ms);
    }
    figures.best_ms.push_back(best);
    figures.segments.push_back(extraction.segments.size());
    if (set.truth.empty()) continue;
    const DetectionEvaluation evaluation =
        EvaluateDetections(set.observable[f], extraction.segments, kMinEdgeLengthPx, {});
    const DetectionEvaluation geometric =
        EvaluateDetections(set.truth[f], extraction.segments, kMinEdgeLengthPx, {});
    figures.all_edges += static_cast<int>(geometric.edges.size());
    figures.all_found += geometric.found;
    figures.edges += static_cast<int>(evaluation.edges.size());
    figures.found += evaluation.found;
    if (!dump_dir.empty()) {
      DumpOverlay(
          dump_dir + "/" + std::to_string(f) + "_" + LineDetectorName(options.detector) + ".png",
          set.images[f], set.camera, extraction.segments, evaluation);
    }
    figures.endpoint_errors.insert(figures.endpoint_errors.end(),
                                   evaluation.endpoint_errors.begin(),
                                   evaluation.endpoint_errors.end());
    figures.offsets_px.insert(figures.offsets_px.end(), evaluation.offsets_px.begin(),
                              evaluation.offsets_px.end());
    figures.angle_errors_deg.insert(figures.angle_errors_deg.end(),
                                    evaluation.angle_errors_deg.begin(),
                                    evaluation.angle_errors_deg.end());
  }
  return figures;
}

std::string Row(const std::string& set, const std::string& detector, const Figures& f,
                bool has_truth) {
  std::ostringstream row;
  row << std::fixed << std::setprecision(2) << "| " << set << " | " << detector << " | "
      << QuantileNearestRank(f.best_ms, 0.5) << " | " << QuantileNearestRank(f.ms, 0.5) << " | "
      << QuantileNearestRank(f.ms, 0.9) << " | " << std::setprecision(0)
      << QuantileNearestRank(f.segments, 0.5) << " | ";
  if (has_truth) {
    row << f.found << " / " << f.edges << " (" << std::setprecision(1)
        << 100.0 * f.found / std::max(1, f.edges) << " %) | " << f.all_found << " / " << f.all_edges
        << " (" << 100.0 * f.all_found / std::max(1, f.all_edges) << " %) | "
        << std::setprecision(2) << QuantileNearestRank(f.endpoint_errors, 0.5) << " / "
        << QuantileNearestRank(f.endpoint_errors, 0.9) << " | " << Rms(f.offsets_px) << " / "
        << Rms(f.angle_errors_deg) << " |";
  } else {
    row << "- | - | - | - |";
  }
  return row.str();
}

int RunBenchLines(const BenchLinesOptions& opt) {
  std::vector<LineDetectorKind> detectors;
  for (const std::string& name : opt.detectors) {
    const auto kind = ParseLineDetector(name);
    if (!kind) throw InputError("--detectors: unknown detector '" + name + "'");
    detectors.push_back(*kind);
  }
  cv::setNumThreads(1);
  const WireframeModel model = LoadModel(opt.model_path);
  const NavigableArea area = NavigableArea::FromModel(model);
  const OcclusionTester occlusion(model);

  std::vector<FrameSet> sets;
  spdlog::info("rendering {} hall views per camera", opt.rendered);
  sets.push_back(RenderedSet("hall rendered, px 1000", SetOptions(opt, PaperSyntheticCamera(), 12),
                             model, area, occlusion));
  sets.push_back(RenderedSet("hall rendered, px 500 + distortion",
                             SetOptions(opt, WideCamera(), 40), model, area, occlusion));
  const std::string cube = opt.visp_images + "/mbt/cube";
  const std::string castle = opt.visp_images + "/mbt-depth/Castle-simu/Images";
  for (const auto& [name, dir, ext] : {std::tuple{"ViSP mbt/cube", cube, ".pgm"},
                                       std::tuple{"ViSP mbt-depth/Castle-simu", castle, ".pgm"}}) {
    std::vector<std::string> files = FilesWithExtension(dir, ext);
    if (files.empty()) {
      spdlog::warn("{}: no {} frames, skipped", dir, ext);
      continue;
    }
    sets.push_back(ReadSet(name, files, opt.max_frames));
  }

  std::ostringstream table;
  table << "640x480 frames, one thread (cv::setNumThreads(1)), " << opt.repeat
        << " timed runs per frame; time = LineExtractor::Extract (detection, undistortion, "
           "merging, length filter); best of runs: the median over frames of each frame's "
           "fastest run (the least disturbed by other processes). Rendered: "
        << opt.rendered << " views per camera, seed " << opt.seed << ", " << opt.clutter
        << " clutter objects. Found: a piece of model edge >= " << kMinEdgeLengthPx
        << " px covered >= 50 % by detections within 2 px and 2 deg of it. Observable pieces: "
           "the parts of the visible edges that no clutter hides and across which the "
           "noise-free image steps by >= 8 grey levels; all visible: the projection with "
           "occlusion by the model only. Endpoint error: each end of a found observable piece "
           "(where it is an end of the visible edge) to the nearest detected endpoint. Line "
           "offset and angle: detections along found pieces against the true line.\n\n"
        << "| frames | detector | median ms (best of runs) | median ms (all runs) | p90 ms (all "
           "runs) | segments (median) | observable model "
           "edges >= 40 px found | all visible edges >= 40 px found | endpoint error px "
           "(median / p90) | line offset px / angle deg (RMS) |\n"
        << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const FrameSet& set : sets) {
    for (LineDetectorKind kind : detectors) {
      LineExtractionOptions options;
      options.detector = kind;
      spdlog::info("{}: {} ({} frames)", set.name, LineDetectorName(kind), set.images.size());
      std::string dump;
      if (!opt.dump_dir.empty() && !set.truth.empty()) {
        dump = opt.dump_dir + "/" + std::to_string(&set - sets.data());
        EnsureDirectory(dump);
      }
      const Figures f = Measure(set, options, opt.repeat, dump);
      table << Row(set.name, LineDetectorName(kind), f, !set.truth.empty()) << "\n";
      if (set.camera && set.camera->has_distortion && kind == LineExtractionOptions().detector) {
        options.undistortion = UndistortionMode::kImage;
        const Figures g = Measure(set, options, opt.repeat);
        table << Row(set.name, LineDetectorName(kind) + " (image remapped)", g, true) << "\n";
      }
    }
  }
  std::cout << table.str();
  if (!opt.out_path.empty()) WriteFileAtomically(opt.out_path, table.str());
  return kExitOk;
}

}  // namespace

void AddBenchLines(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchLinesOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "lines",
      "Line detectors side by side (time per 640x480 frame, one thread; edges found and "
      "endpoint error on rendered hall views)");
  cmd->add_option("--model", opt->model_path, "Model rendered")->capture_default_str();
  cmd->add_option("--visp-images", opt->visp_images, "ViSP-images folder (visp-images-data)")
      ->capture_default_str();
  cmd->add_option("--rendered", opt->rendered, "Rendered views per camera")->capture_default_str();
  cmd->add_option("--max-frames", opt->max_frames, "Frames taken from each ViSP sequence")
      ->capture_default_str();
  cmd->add_option("--repeat", opt->repeat, "Timed runs per frame")->capture_default_str();
  cmd->add_option("--clutter", opt->clutter, "Unmodelled objects in the rendered hall")
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the rendered views")->capture_default_str();
  cmd->add_option("--detectors", opt->detectors, "Detectors: hough lsd fld edlines")
      ->capture_default_str();
  cmd->add_option("--out", opt->out_path, "Also write the table (Markdown) to this file");
  cmd->add_option("--dump", opt->dump_dir,
                  "Write overlays of the rendered views here (detections red, model edges found "
                  "green, missed blue)");
  cmd->callback([opt, action] {
    if (opt->rendered < 1 || opt->max_frames < 1 || opt->repeat < 1 || opt->clutter < 0) {
      throw CLI::ValidationError("--rendered, --max-frames, --repeat >= 1, --clutter >= 0");
    }
    *action = [opt] { return RunBenchLines(*opt); };
  });
}

}  // namespace linetrack::app

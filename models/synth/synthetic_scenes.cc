// Synthetic localisation scenes: pose, projection with a calibration error, line noise and
// fragmentation, clutter, prior, shuffle (docs/synth.md).
#include "models/synth/synthetic_scenes.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "models/errors.h"

namespace linetrack {
namespace {

constexpr int kMaxPositionDraws = 1000000;  // rejection sampling in the navigable area
constexpr int kMaxClutterDraws = 100;       // per clutter line before giving up on it
constexpr double kClutterWallMarginM = 0.05;

// An image line and what it is: a model edge's id, or -1 for clutter.
struct LabelledLine {
  Segment2 line;
  int edge_id = -1;
  bool vertical_clutter = false;
};

CameraIntrinsics ImageCamera(const CameraIntrinsics& nominal, double calibration_error) {
  CameraIntrinsics camera = nominal.Undistorted();
  camera.px *= 1.0 + calibration_error;
  camera.py *= 1.0 + calibration_error;
  return camera;
}

Eigen::Vector2d RandomPosition(const NavigableArea& area, int storey, SceneRandom* rng) {
  const Eigen::Vector2d lo = area.BoundsMin(storey), hi = area.BoundsMax(storey);
  for (int i = 0; i < kMaxPositionDraws; ++i) {
    const Eigen::Vector2d p(rng->Uniform(lo.x(), hi.x()), rng->Uniform(lo.y(), hi.y()));
    if (area.Contains(p, storey)) return p;
  }
  throw InputError(area.source() + ": no position of the navigable area found by sampling");
}

// The measured pieces of one image segment: line noise, then (when `fragment`) shortening and
// splitting, then clipping to the image and the length threshold. Draws the same number of
// random values whatever the outcome.
std::vector<Segment2> MeasuredPieces(const Segment2& image, bool fragment,
                                     const SyntheticSceneOptions& o, SceneRandom* rng) {
  const double angle = rng->Normal(o.angle_sigma);
  const double offset = rng->Normal(o.offset_sigma_px);
  const Segment2 noisy = PerturbSegment(image, angle, offset);
  std::vector<Segment2> pieces = {noisy};
  if (fragment) {
    const double cut_a = rng->Uniform(0.0, o.shorten_max);
    const double cut_b = rng->Uniform(0.0, o.shorten_max);
    const bool split = rng->Bernoulli(o.split_probability);
    const double split_at = rng->Uniform(0.25, 0.75);
    const double gap = rng->Uniform(0.0, o.split_gap);
    pieces = FragmentSegment(noisy, cut_a, cut_b, split_at, split ? gap : 0.0);
  }
  std::vector<Segment2> kept;
  for (Segment2& piece : pieces) {
    if (ClipSegmentToImage(o.camera.width, o.camera.height, &piece) &&
        piece.Length() >= o.min_length_px) {
      kept.push_back(piece);
    }
  }
  return kept;
}

// The image of a random unmodelled vertical segment standing on the floor in front of the
// camera, visible (not behind a wall) and long enough; nullopt when none was found.
std::optional<Segment2> VerticalClutterLine(const RobotPose& truth, const CameraIntrinsics& camera,
                                            const OcclusionTester& occlusion,
                                            const NavigableArea& area,
                                            const SyntheticSceneOptions& o, SceneRandom* rng) {
  const Eigen::Isometry3d cam_from_world = CamFromWorld(truth);
  const double half_fov = std::atan2(0.5 * camera.width, camera.px);
  for (int i = 0; i < kMaxClutterDraws; ++i) {
    const double bearing = truth.heading + rng->Uniform(-half_fov, half_fov);
    const double distance =
        rng->Uniform(o.vertical_clutter_distance_min, o.vertical_clutter_distance_max);
    const double top = rng->Uniform(o.vertical_clutter_height_min, o.vertical_clutter_height_max);
    const Eigen::Vector2d foot = Eigen::Vector2d(truth.x, truth.y) +
                                 distance * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
    if (!area.InsideWalls(foot, kClutterWallMarginM, o.storey)) continue;
    Segment3 segment{{foot.x(), foot.y(), o.floor_z}, {foot.x(), foot.y(), o.floor_z + top}};
    if (!ClipToFrustum(cam_from_world, camera, EdgeProjectionOptions().near_clip, &segment) ||
        occlusion.Blocked(truth.Centre(), segment.a) ||
        occlusion.Blocked(truth.Centre(), segment.b)) {
      continue;
    }
    const Segment2 image{camera.Project(cam_from_world * segment.a),
                         camera.Project(cam_from_world * segment.b)};
    const std::vector<Segment2> pieces = MeasuredPieces(image, false, o, rng);
    if (pieces.empty()) continue;
    return pieces.front();
  }
  return std::nullopt;
}

// A random image segment: midpoint uniform in the image, direction uniform, length uniform in
// the clutter range, clipped to the image; false when none was long enough.
bool RandomClutterLine(const SyntheticSceneOptions& o, SceneRandom* rng, Segment2* line) {
  for (int i = 0; i < kMaxClutterDraws; ++i) {
    const Eigen::Vector2d mid(rng->Uniform(0.0, o.camera.width - 1.0),
                              rng->Uniform(0.0, o.camera.height - 1.0));
    const double angle = rng->Uniform(0.0, kPi);
    const double length = rng->Uniform(o.clutter_length_min_px, o.clutter_length_max_px);
    const Eigen::Vector2d half = 0.5 * length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    Segment2 s{mid - half, mid + half};
    if (ClipSegmentToImage(o.camera.width, o.camera.height, &s) && s.Length() >= o.min_length_px) {
      *line = s;
      return true;
    }
  }
  return false;
}

// The model lines seen from `truth` through `camera`, measured; empty when the number of edges
// they show is outside the accepted range.
std::vector<LabelledLine> ModelLines(const WireframeModel& model, const OcclusionTester& occlusion,
                                     const RobotPose& truth, const CameraIntrinsics& camera,
                                     const SyntheticSceneOptions& o, SceneRandom* rng) {
  EdgeProjectionOptions projection;
  projection.min_length_px = o.min_length_px;
  std::vector<LabelledLine> lines;
  for (const ProjectedEdge& edge :
       ProjectVisibleEdges(model, occlusion, CamFromWorld(truth), camera, projection)) {
    for (const Segment2& piece : MeasuredPieces(edge.image, true, o, rng)) {
      lines.push_back({piece, edge.edge_id, false});
    }
  }
  int edges = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    edges += i == 0 || lines[i].edge_id != lines[i - 1].edge_id ? 1 : 0;  // grouped by edge
  }
  if (edges < o.min_visible_edges || edges > o.max_visible_edges) lines.clear();
  return lines;
}

// `count` lines parallel to model lines of `lines` (SyntheticSceneOptions::parallel_clutter),
// appended as clutter; drawn from `rng`, a stream of their own.
void AddParallelClutter(int count, const SyntheticSceneOptions& o, SceneRandom* rng,
                        std::vector<LabelledLine>* lines) {
  std::vector<Segment2> model_lines;
  for (const LabelledLine& line : *lines) {
    if (line.edge_id >= 0) model_lines.push_back(line.line);
  }
  if (model_lines.empty()) return;
  for (int k = 0; k < count; ++k) {
    const Segment2& beside = model_lines[rng->Integer(0, static_cast<int>(model_lines.size()) - 1)];
    const double offset = rng->Uniform(o.parallel_offset_min_px, o.parallel_offset_max_px) *
                          (rng->Bernoulli(0.5) ? 1.0 : -1.0);
    const double share = rng->Uniform(0.3, 1.0);
    const double start = rng->Uniform(0.0, 1.0 - share);
    const Segment2 stretch{beside.a + start * (beside.b - beside.a),
                           beside.a + (start + share) * (beside.b - beside.a)};
    Segment2 twin = PerturbSegment(stretch, rng->Normal(o.angle_sigma),
                                   offset + rng->Normal(o.offset_sigma_px));
    if (ClipSegmentToImage(o.camera.width, o.camera.height, &twin) &&
        twin.Length() >= o.min_length_px) {
      lines->push_back({twin, -1, false});
    }
  }
}

// Shuffles the lines (Fisher-Yates) and fills the scene's lines and ground truth.
void AssembleLines(std::vector<LabelledLine> lines, SceneRandom* rng, SyntheticScene* scene) {
  for (int i = static_cast<int>(lines.size()) - 1; i > 0; --i) {
    std::swap(lines[i], lines[rng->Integer(0, i)]);
  }
  for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
    scene->lines.push_back(lines[i].line);
    if (lines[i].edge_id >= 0) {
      scene->matches.emplace_back(lines[i].edge_id, i);
    } else {
      scene->clutter.push_back(i);
      if (lines[i].vertical_clutter) scene->vertical_clutter.push_back(i);
    }
  }
  std::sort(scene->matches.begin(), scene->matches.end());
}

}  // namespace

SyntheticScene GenerateScene(const WireframeModel& model, const OcclusionTester& occlusion,
                             const NavigableArea& area, const SyntheticSceneOptions& o, int index) {
  std::string why;
  if (!o.Check(&why)) throw InputError("synthetic scenes: " + why);
  SceneRandom rng(o.seed, static_cast<uint64_t>(index));
  SyntheticScene scene;
  scene.index = index;
  std::vector<LabelledLine> lines;
  CameraIntrinsics camera;
  while (lines.empty()) {
    if (++scene.attempts > o.max_attempts) {
      throw InputError(model.path() + ": no pose in " + std::to_string(o.max_attempts) +
                       " draws sees " + std::to_string(o.min_visible_edges) + " to " +
                       std::to_string(o.max_visible_edges) + " model edges");
    }
    const Eigen::Vector2d position = RandomPosition(area, o.storey, &rng);
    scene.truth.x = position.x();
    scene.truth.y = position.y();
    scene.truth.heading = rng.Uniform(-kPi, kPi);
    scene.truth.height = o.floor_z + rng.Uniform(o.height_min, o.height_max);
    scene.truth.tilt = rng.Uniform(o.tilt_min, o.tilt_max);
    scene.calibration_error = rng.Normal(o.calibration_sigma);
    camera = ImageCamera(o.camera, scene.calibration_error);
    lines = ModelLines(model, occlusion, scene.truth, camera, o, &rng);
  }
  const int clutter = rng.Integer(o.min_clutter, o.max_clutter);
  const int vertical = static_cast<int>(std::lround(clutter * o.vertical_clutter_fraction));
  for (int k = 0; k < clutter; ++k) {
    LabelledLine line;
    const std::optional<Segment2> vertical_line =
        k < vertical ? VerticalClutterLine(scene.truth, camera, occlusion, area, o, &rng)
                     : std::nullopt;
    line.vertical_clutter = vertical_line.has_value();
    if (vertical_line) line.line = *vertical_line;
    if (line.vertical_clutter || RandomClutterLine(o, &rng, &line.line)) lines.push_back(line);
  }
  const double radius = o.delta_t * std::sqrt(rng.Uniform(0.0, 1.0));
  const double direction = rng.Uniform(-kPi, kPi);
  scene.prior = {scene.truth.x + radius * std::cos(direction),
                 scene.truth.y + radius * std::sin(direction),
                 WrapAngle(scene.truth.heading + rng.Uniform(-o.delta_phi, o.delta_phi))};
  scene.delta_t = o.delta_t;
  scene.delta_phi = o.delta_phi;
  scene.height = scene.truth.height;
  scene.tilt = scene.truth.tilt;
  if (o.parallel_clutter > 0) {
    SceneRandom parallel(o.seed ^ 0x9e3779b97f4a7c15ULL, static_cast<uint64_t>(index));
    AddParallelClutter(o.parallel_clutter, o, &parallel, &lines);
  }
  AssembleLines(std::move(lines), &rng, &scene);
  return scene;
}

std::vector<SyntheticScene> GenerateScenes(const WireframeModel& model, const NavigableArea& area,
                                           const SyntheticSceneOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("synthetic scenes: " + why);
  const OcclusionTester occlusion(model);
  std::vector<SyntheticScene> scenes;
  scenes.reserve(options.count);
  for (int i = 0; i < options.count; ++i) {
    scenes.push_back(GenerateScene(model, occlusion, area, options, i));
  }
  return scenes;
}

}  // namespace linetrack

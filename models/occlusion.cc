#include "models/occlusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {
namespace {

// Crossing-number test of a 2D point against a polygon.
bool InsidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

// The segment of sight from `eye` to `target` with what every face's test needs: its direction,
// length and box, and the tolerance (metres) within which a face through `target` does not count.
struct SightLine {
  SightLine(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, double tolerance)
      : eye(eye),
        dir(target - eye),
        lo(eye.cwiseMin(target)),
        hi(eye.cwiseMax(target)),
        length(dir.norm()),
        tolerance(tolerance) {}

  // True when `face` crosses the open segment before the target (OcclusionTester::Blocked).
  template <typename Face>
  bool Crosses(const Face& face) const {
    if ((face.box_max.array() < lo.array() - tolerance).any() ||
        (face.box_min.array() > hi.array() + tolerance).any()) {
      return false;
    }
    const double denom = face.normal.dot(dir);
    if (std::abs(denom) < 1e-12) return false;  // parallel to the face
    const double t = (face.offset - face.normal.dot(eye)) / denom;
    if (t <= 0.0 || t * length >= length - tolerance) return false;
    const Eigen::Vector3d hit = eye + t * dir;
    return InsidePolygon(face.polygon, Eigen::Vector2d(hit[face.axis_u], hit[face.axis_v]));
  }

  Eigen::Vector3d eye, dir, lo, hi;
  double length = 0.0, tolerance = 0.0;
};

// Faces are listed in the grid cells their plan box, grown by this (metres), meets: far above the
// rounding of a hit point; cells are no smaller than kMinCell (metres).
constexpr double kPlanMargin = 1e-6;
constexpr double kMinCell = 0.25;
constexpr size_t kFacesWithoutGrid = 64;

}  // namespace

OcclusionTester::OcclusionTester(const WireframeModel& model) {
  for (const ModelFace& f : model.faces()) {
    if (f.Degenerate()) continue;
    Face face;
    face.normal = f.normal;
    face.offset = f.offset;
    int drop = 0;
    f.normal.cwiseAbs().maxCoeff(&drop);  // project along the dominant normal axis
    face.axis_u = (drop + 1) % 3;
    face.axis_v = (drop + 2) % 3;
    face.box_min = face.box_max = f.corners.front();
    for (const Eigen::Vector3d& c : f.corners) {
      face.polygon.emplace_back(c[face.axis_u], c[face.axis_v]);
      face.box_min = face.box_min.cwiseMin(c);
      face.box_max = face.box_max.cwiseMax(c);
    }
    faces_.push_back(std::move(face));
  }
  BuildPlanGrid(model);
}

void OcclusionTester::BuildPlanGrid(const WireframeModel& model) {
  // Layers split in the middle of each slab between two storeys (floor of the upper one, top of
  // the lower one): a sight line within a storey meets the faces of its own layer only.
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> cuts = {-inf};
  const std::vector<Storey>& storeys = model.storeys();
  for (size_t s = 1; s < storeys.size(); ++s) {
    const double cut = 0.5 * (storeys[s - 1].top_z + storeys[s].floor_z);
    if (cut > cuts.back()) cuts.push_back(cut);
  }
  cuts.push_back(inf);
  for (size_t k = 0; k + 1 < cuts.size(); ++k)
    layers_.push_back({cuts[k], cuts[k + 1], {}});
  if (faces_.empty()) {
    for (Layer& layer : layers_)
      layer.cells.assign(1, {});
    return;
  }
  Eigen::Vector2d lo = faces_.front().box_min.head<2>(), hi = faces_.front().box_max.head<2>();
  for (const Face& face : faces_)
    lo = lo.cwiseMin(face.box_min.head<2>()), hi = hi.cwiseMax(face.box_max.head<2>());
  lo -= Eigen::Vector2d::Constant(kPlanMargin);
  hi += Eigen::Vector2d::Constant(kPlanMargin);
  const Eigen::Vector2d extent = hi - lo;
  cell_ = std::max(kMinCell, std::sqrt(extent.prod() / static_cast<double>(faces_.size())));
  origin_ = lo;
  cols_ = static_cast<int>(extent.x() / cell_) + 1;
  rows_ = static_cast<int>(extent.y() / cell_) + 1;
  for (Layer& layer : layers_)
    layer.cells.assign(static_cast<size_t>(cols_) * rows_, {});
  for (size_t i = 0; i < faces_.size(); ++i) {
    const Face& face = faces_[i];
    const Eigen::Vector2d a = face.box_min.head<2>() - Eigen::Vector2d::Constant(kPlanMargin);
    const Eigen::Vector2d b = face.box_max.head<2>() + Eigen::Vector2d::Constant(kPlanMargin);
    const Eigen::Vector4i r(Col(a.x()), Col(b.x()), Row(a.y()), Row(b.y()));
    for (Layer& layer : layers_) {
      if (face.box_max.z() < layer.z_lo || face.box_min.z() > layer.z_hi) continue;
      for (int row = r[2]; row <= r[3]; ++row) {
        for (int col = r[0]; col <= r[1]; ++col)
          layer.cells[static_cast<size_t>(row) * cols_ + col].push_back(static_cast<int>(i));
      }
    }
    rectangles_.push_back(r);
  }
}

int OcclusionTester::Col(double x) const {
  return std::clamp(static_cast<int>(std::floor((x - origin_.x()) / cell_)), 0, cols_ - 1);
}

int OcclusionTester::Row(double y) const {
  return std::clamp(static_cast<int>(std::floor((y - origin_.y()) / cell_)), 0, rows_ - 1);
}

template <typename Test>
bool OcclusionTester::AlongPlan(const Layer& layer, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Test& test) const {
  // Cells of the plan segment a -> b (Amanatides-Woo); the segment is not clipped to the grid:
  // outside it, cells are clamped to its border, which lists every face there may be.
  const Eigen::Vector2d p = a.head<2>(), d = b.head<2>() - p;
  int c = Col(p.x()), r = Row(p.y());
  const int c_end = Col(b.x()), r_end = Row(b.y());
  const int step_c = d.x() > 0 ? 1 : -1, step_r = d.y() > 0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double dt_c = std::abs(d.x()) > 1e-300 ? cell_ / std::abs(d.x()) : inf;
  const double dt_r = std::abs(d.y()) > 1e-300 ? cell_ / std::abs(d.y()) : inf;
  double t_c = std::abs(d.x()) > 1e-300
                   ? (origin_.x() + (c + (step_c > 0 ? 1 : 0)) * cell_ - p.x()) / d.x()
                   : inf;
  double t_r = std::abs(d.y()) > 1e-300
                   ? (origin_.y() + (r + (step_r > 0 ? 1 : 0)) * cell_ - p.y()) / d.y()
                   : inf;
  int prev_c = -1, prev_r = -1;
  for (int guard = 0; guard < cols_ + rows_ + 2; ++guard) {
    for (int i : layer.cells[static_cast<size_t>(r) * cols_ + c]) {
      // A face met in the previous cell was tested there (the walk is contiguous in its box).
      const Eigen::Vector4i& box = rectangles_[i];
      if (prev_c >= box[0] && prev_c <= box[1] && prev_r >= box[2] && prev_r <= box[3]) continue;
      if (test(i)) return true;
    }
    if (c == c_end && r == r_end) break;
    prev_c = c, prev_r = r;
    if (t_c < t_r) {
      c += step_c;
      t_c += dt_c;
    } else {
      r += step_r;
      t_r += dt_r;
    }
    if (c < 0 || r < 0 || c >= cols_ || r >= rows_) break;
  }
  return false;
}

bool OcclusionTester::Blocked(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                              double tolerance) const {
  // A model of a few faces (one room) is quicker to test face by face than to walk.
  if (faces_.size() <= kFacesWithoutGrid) return BlockedByAnyFace(eye, target, tolerance);
  if ((target - eye).norm() <= tolerance) return false;
  // Only a face whose z extent meets the segment's, grown by the tolerance, can cross it
  // (SightLine::Crosses' box test): such a face is listed in a layer that the grown extent meets.
  const SightLine sight(eye, target, tolerance);
  const double z_lo = sight.lo.z() - tolerance, z_hi = sight.hi.z() + tolerance;
  const auto crosses = [&](int i) { return sight.Crosses(faces_[i]); };
  for (const Layer& layer : layers_) {
    if (layer.z_hi < z_lo || layer.z_lo > z_hi) continue;
    if (AlongPlan(layer, eye, target, crosses)) return true;
  }
  return false;
}

bool OcclusionTester::BlockedByAnyFace(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                       double tolerance) const {
  if ((target - eye).norm() <= tolerance) return false;
  const SightLine sight(eye, target, tolerance);
  return std::any_of(faces_.begin(), faces_.end(),
                     [&](const Face& face) { return sight.Crosses(face); });
}

bool ClipToFrustum(const Eigen::Isometry3d& cam_from_world, const CameraIntrinsics& camera,
                   double near_clip, Segment3* segment) {
  const Eigen::Vector3d a = cam_from_world * segment->a;
  const Eigen::Vector3d b = cam_from_world * segment->b;
  const double w = camera.width - 1.0, h = camera.height - 1.0;
  // Half-spaces n . X + d >= 0 in camera coordinates.
  const Eigen::Vector4d planes[] = {
      {0.0, 0.0, 1.0, -near_clip},           {camera.px, 0.0, camera.u0, 0.0},  // u >= 0
      {-camera.px, 0.0, w - camera.u0, 0.0},                                    // u <= w
      {0.0, camera.py, camera.v0, 0.0},                                         // v >= 0
      {0.0, -camera.py, h - camera.v0, 0.0},                                    // v <= h
  };
  double t0 = 0.0, t1 = 1.0;
  for (const Eigen::Vector4d& p : planes) {
    const double fa = p.head<3>().dot(a) + p[3];
    const double fb = p.head<3>().dot(b) + p[3];
    if (fa < 0.0 && fb < 0.0) return false;
    if (fa < 0.0) t0 = std::max(t0, fa / (fa - fb));
    if (fb < 0.0) t1 = std::min(t1, fa / (fa - fb));
    if (t0 >= t1) return false;
  }
  const Eigen::Vector3d wa = segment->a, wb = segment->b;
  segment->a = wa + t0 * (wb - wa);
  segment->b = wa + t1 * (wb - wa);
  return true;
}

std::vector<ProjectedEdge> ProjectVisibleEdges(const WireframeModel& model,
                                               const OcclusionTester& occlusion,
                                               const Eigen::Isometry3d& cam_from_world,
                                               const CameraIntrinsics& camera,
                                               const EdgeProjectionOptions& options) {
  std::vector<ProjectedEdge> out;
  const Eigen::Vector3d eye = cam_from_world.inverse().translation();
  auto pixel = [&](const Eigen::Vector3d& world) { return camera.Project(cam_from_world * world); };
  for (const ModelEdge& edge : model.edges()) {
    Segment3 clipped = edge.segment;
    if (!ClipToFrustum(cam_from_world, camera, options.near_clip, &clipped)) continue;
    const double image_length = (pixel(clipped.b) - pixel(clipped.a)).norm();
    const int samples =
        std::max(2, static_cast<int>(std::ceil(image_length / options.sample_step_px)) + 1);
    // Sample along the world segment (samples are not uniform in the image; the step is an
    // upper bound on average). A run of visible samples becomes one visible piece.
    int run_start = -1;
    auto emit = [&](int first, int last) {
      const double ta = static_cast<double>(first) / (samples - 1);
      const double tb = static_cast<double>(last) / (samples - 1);
      ProjectedEdge piece;
      piece.edge_id = edge.id;
      piece.world = {clipped.a + ta * (clipped.b - clipped.a),
                     clipped.a + tb * (clipped.b - clipped.a)};
      piece.image = {pixel(piece.world.a), pixel(piece.world.b)};
      if (piece.image.Length() >= options.min_length_px) out.push_back(piece);
    };
    for (int i = 0; i < samples; ++i) {
      const double t = static_cast<double>(i) / (samples - 1);
      const bool visible = !occlusion.Blocked(eye, clipped.a + t * (clipped.b - clipped.a));
      if (visible && run_start < 0) run_start = i;
      if (!visible && run_start >= 0) {
        emit(run_start, i - 1);
        run_start = -1;
      }
    }
    if (run_start >= 0) emit(run_start, samples - 1);
  }
  return out;
}

}  // namespace linetrack

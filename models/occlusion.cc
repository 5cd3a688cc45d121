#include "models/occlusion.h"

#include <algorithm>
#include <cmath>

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
}

bool OcclusionTester::Blocked(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                              double tolerance) const {
  const Eigen::Vector3d dir = target - eye;
  const double length = dir.norm();
  if (length <= tolerance) return false;
  const Eigen::Vector3d lo = eye.cwiseMin(target), hi = eye.cwiseMax(target);
  for (const Face& face : faces_) {
    if ((face.box_max.array() < lo.array() - tolerance).any() ||
        (face.box_min.array() > hi.array() + tolerance).any()) {
      continue;
    }
    const double denom = face.normal.dot(dir);
    if (std::abs(denom) < 1e-12) continue;  // parallel to the face
    const double t = (face.offset - face.normal.dot(eye)) / denom;
    if (t <= 0.0 || t * length >= length - tolerance) continue;
    const Eigen::Vector3d hit = eye + t * dir;
    if (InsidePolygon(face.polygon, Eigen::Vector2d(hit[face.axis_u], hit[face.axis_v]))) {
      return true;
    }
  }
  return false;
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

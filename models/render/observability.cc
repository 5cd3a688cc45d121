#include "models/render/observability.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace linetrack {
namespace {

constexpr double kSamplesPerPixel = 1.5;  // samples along an edge piece per pixel of its image

bool Unmodelled(SurfaceKind kind) {
  return kind == SurfaceKind::kClutter || kind == SurfaceKind::kPerson;
}

// True when the map shows an unmodelled surface nearer than the point at depth z (camera frame)
// seen through pixel uv.
bool HiddenByUnmodelled(const SurfaceMap& seen, const RenderScene& scene, const Eigen::Vector2d& uv,
                        double z, double margin) {
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  if (u < 0 || v < 0 || u >= seen.width || v >= seen.height) return false;
  const int id = seen.At(u, v);
  if (id < 0 || !Unmodelled(scene.surfaces[id].kind)) return false;
  return seen.DepthAt(u, v) < z * 0.99 - margin;
}

// Longest run (pixels) of samples along the piece that nothing unmodelled hides.
double LongestUnhiddenRun(const ProjectedEdge& piece, const Eigen::Isometry3d& cam_from_world,
                          const CameraIntrinsics& camera, const SurfaceMap& seen,
                          const RenderScene& scene, double margin) {
  const Eigen::Vector3d a = cam_from_world * piece.world.a, b = cam_from_world * piece.world.b;
  const double image_length = (piece.image.b - piece.image.a).norm();
  const int n = std::max(2, static_cast<int>(std::ceil(kSamplesPerPixel * image_length)));
  double run = 0.0, longest = 0.0;
  Eigen::Vector2d previous;
  bool previous_visible = false;
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / n);
    if (p.z() <= 0.0) {
      previous_visible = false;
      continue;
    }
    const Eigen::Vector2d uv = camera.Project(p);
    const bool visible = !HiddenByUnmodelled(seen, scene, uv, p.z(), margin);
    if (visible && previous_visible) {
      run += (uv - previous).norm();
    } else if (visible) {
      run = 0.0;
    }
    longest = std::max(longest, visible ? run : 0.0);
    previous = uv;
    previous_visible = visible;
  }
  return longest;
}

}  // namespace

bool ObservabilityOptions::Check(std::string* why) const {
  if (!(min_edge_px > 0.0 && min_edge_px < 1e5) || min_edges < 1 ||
      !(occluder_margin >= 0.0 && occluder_margin < 1.0)) {
    *why = "observability needs min_edge_px > 0, min_edges >= 1 and a margin in [0, 1) m";
    return false;
  }
  return true;
}

FrameObservation ObserveFrame(const WireframeModel& model, const OcclusionTester& occlusion,
                              const CameraIntrinsics& camera,
                              const Eigen::Isometry3d& cam_from_world, const SurfaceMap& seen,
                              const RenderScene& scene, const ObservabilityOptions& options) {
  FrameObservation out;
  std::map<int, double> longest;  // edge id -> longest unhidden piece (pixels)
  for (const ProjectedEdge& piece : ProjectVisibleEdges(model, occlusion, cam_from_world, camera)) {
    const double run =
        LongestUnhiddenRun(piece, cam_from_world, camera, seen, scene, options.occluder_margin);
    longest[piece.edge_id] = std::max(longest[piece.edge_id], run);
  }
  for (const auto& [id, run] : longest) {
    if (run >= options.min_edge_px) ++out.edges;
  }
  out.observable = out.edges >= options.min_edges;
  size_t people = 0, clutter = 0;
  for (const int id : seen.surface) {
    if (id < 0) continue;
    people += scene.surfaces[id].kind == SurfaceKind::kPerson;
    clutter += scene.surfaces[id].kind == SurfaceKind::kClutter;
  }
  const double pixels = std::max<size_t>(1, seen.surface.size());
  out.people_share = people / pixels;
  out.clutter_share = clutter / pixels;
  const float depth = seen.width > 0 ? seen.DepthAt(seen.width / 2, seen.height / 2) : 0.0f;
  out.centre_depth_m = depth;
  return out;
}

}  // namespace linetrack

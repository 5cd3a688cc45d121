// Exact synthetic views of the bundled hall for the matcher's tests: seeded random robot poses
// in the navigable area and the visible pieces of the model edges projected without noise.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "matching/pose_refinement.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/wireframe.h"

namespace linetrack::testing {

struct ExactView {
  RobotPose pose;
  std::vector<ProjectedEdge> pieces;  // visible pieces, >= min length
};

class HallFixture {
 public:
  HallFixture()
      : model_(WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao")),
        area_(NavigableArea::FromModel(model_, AreaOptions())),
        occlusion_(model_) {
    camera_.width = 640;
    camera_.height = 480;
    camera_.px = camera_.py = 1000.0;
    camera_.u0 = 320.0;
    camera_.v0 = 240.0;
  }

  const WireframeModel& model() const { return model_; }
  const NavigableArea& area() const { return area_; }
  const CameraIntrinsics& camera() const { return camera_; }

  // A random pose (height 1.2-1.5 m, tilt 0-10 deg) seeing at least `min_pieces` pieces.
  ExactView RandomView(std::mt19937_64& rng, int min_pieces = 5,
                       double min_length_px = 20.0) const {
    std::uniform_real_distribution<double> ux(area_.BoundsMin().x(), area_.BoundsMax().x());
    std::uniform_real_distribution<double> uy(area_.BoundsMin().y(), area_.BoundsMax().y());
    std::uniform_real_distribution<double> uh(-kPi, kPi), uz(1.2, 1.5), ut(0.0, DegToRad(10.0));
    for (;;) {
      ExactView view;
      view.pose = {ux(rng), uy(rng), uh(rng), uz(rng), ut(rng)};
      if (!area_.Contains({view.pose.x, view.pose.y})) continue;
      EdgeProjectionOptions options;
      options.min_length_px = min_length_px;
      view.pieces =
          ProjectVisibleEdges(model_, occlusion_, CamFromWorld(view.pose), camera_, options);
      if (static_cast<int>(view.pieces.size()) >= min_pieces) return view;
    }
  }

 private:
  static NavigableAreaOptions AreaOptions() {
    NavigableAreaOptions options;
    options.sidecar_path = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/hall.nav.json";
    return options;
  }

  WireframeModel model_;
  NavigableArea area_;
  OcclusionTester occlusion_;
  CameraIntrinsics camera_;
};

// The correspondences of an exact view: each visible piece's image matched to its whole model
// edge (identity whitening).
inline std::vector<LineMatch> ExactLineMatches(const HallFixture& hall, const ExactView& view) {
  std::vector<LineMatch> matches;
  for (const ProjectedEdge& p : view.pieces) {
    const ModelEdge& e = hall.model().edges()[p.edge_id];
    matches.push_back({e.segment.a, e.segment.b, p.image});
  }
  return matches;
}

// The paper's line noise (Table 1): the segment rotated about its midpoint by N(0, angle) and
// shifted along its normal by N(0, offset); the ends shortened by up to `shorten` each.
inline Segment2 NoisySegment(const Segment2& s, double offset_px, double angle_deg, double shorten,
                             std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector2d mid = s.Mid();
  const double length = s.Length();
  const double angle = DegToRad(angle_deg) * normal(rng);
  const Eigen::Vector2d d = (s.b - s.a) / length;
  const Eigen::Vector2d dir(std::cos(angle) * d.x() - std::sin(angle) * d.y(),
                            std::sin(angle) * d.x() + std::cos(angle) * d.y());
  const Eigen::Vector2d shift = offset_px * normal(rng) * Eigen::Vector2d(-dir.y(), dir.x());
  const double t0 = -0.5 * length + shorten * length * unit(rng);
  const double t1 = 0.5 * length - shorten * length * unit(rng);
  return {mid + shift + t0 * dir, mid + shift + t1 * dir};
}

}  // namespace linetrack::testing

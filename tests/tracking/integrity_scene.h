// Exact synthetic edge measurements for the integrity tests: known model edges seen from a known
// pose with the project's camera conventions, points sampled along their images, and seeded
// errors that follow docs/integrity.md's model (point noise, per-edge offsets at the ends from
// model error and latching, intrinsics, a robot's height, tilt and roll).
#pragma once

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "tracking/integrity/edge_pose_solver.h"

namespace linetrack {
namespace integrity_test {

// 640 x 480, px = py = 500 (the wide test camera without its distortion).
inline CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = 500.0;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  return camera;
}

// A room 6 m deep (x from 2 to 8 m), 4 m wide (y from -2 to 2) and 3 m high, with two door
// frames in each side wall: its floor, ceiling and corner edges and the doors' verticals and
// lintels.
inline std::vector<Segment3> RoomEdges() {
  std::vector<Segment3> edges;
  auto add = [&](Eigen::Vector3d a, Eigen::Vector3d b) { edges.push_back({a, b}); };
  for (double y : {-2.0, 2.0}) {
    for (double z : {0.0, 3.0})
      add({2.0, y, z}, {8.0, y, z});
    add({8.0, y, 0.0}, {8.0, y, 3.0});
    for (double x0 : {3.5, 5.5}) {
      add({x0, y, 0.0}, {x0, y, 2.1});
      add({x0 + 0.9, y, 0.0}, {x0 + 0.9, y, 2.1});
      add({x0, y, 2.1}, {x0 + 0.9, y, 2.1});
    }
  }
  add({8.0, -2.0, 0.0}, {8.0, 2.0, 0.0});
  add({8.0, -2.0, 3.0}, {8.0, 2.0, 3.0});
  return edges;
}

// The robot pose of the tests: at the room's near end looking down it, slightly turned.
inline RobotPose TestRobotPose() {
  return RobotPose{0.4, -0.3, DegToRad(6.0), 1.3, DegToRad(5.0)};
}

// Errors to draw (standard deviations); zero: none.
struct SceneNoise {
  double point_px = 0.0;
  double model_m = 0.0;
  double latch_px = 0.0;
  double focal_relative = 0.0;
  double principal_point_px = 0.0;
  double height_m = 0.0;
  double tilt_rad = 0.0;
  double roll_rad = 0.0;
  double sample_step_px = 8.0;  // spacing of the points along each edge's image
  double end_margin_px = 4.0;
};

// The noise model that the solver assumes for `noise` (same sigmas).
inline EdgePoseSolverOptions SolverOptionsFor(const SceneNoise& noise) {
  EdgePoseSolverOptions options;
  options.noise.min_point_sigma_px = std::max(1e-3, 0.5 * noise.point_px);
  options.noise.model_sigma_m = noise.model_m;
  options.noise.latch_sigma_px = noise.latch_px;
  options.considered.focal_relative = noise.focal_relative;
  options.considered.principal_point_px = noise.principal_point_px;
  options.considered.height_m = noise.height_m;
  options.considered.tilt_rad = noise.tilt_rad;
  options.considered.roll_rad = noise.roll_rad;
  return options;
}

// The edge noise of the monitor tests: 0.15 px per point, 5 mm of model error per end, a 0.3 px
// latch per edge.
inline SceneNoise RealisticNoise() {
  SceneNoise noise;
  noise.point_px = 0.15;
  noise.model_m = 0.005;
  noise.latch_px = 0.3;
  return noise;
}

// The robot of TestRobotPose() with its height and tilt known: x, y, heading.
inline PoseParameterisation RobotParameters() {
  return PoseParameterisation(KnownHeightTilt{TestRobotPose().height, TestRobotPose().tilt});
}

// The solver's start: 2.2 cm and 0.3 degree from the truth.
inline Eigen::Isometry3d Start(const Eigen::Isometry3d& truth) {
  WorldTwist offset;
  offset << 0.02, -0.01, 0.0, 0.0, 0.0, DegToRad(0.3);
  return ApplyWorldTwist(truth, offset);
}

// The observations of `edges` (world) seen by `camera` from `cam_from_world`: each edge clipped
// to the view, points every sample_step_px along its image (end_margin_px from the ends), each
// moved along the image normal by point noise plus (1 - t) o_a + t o_b + l, o ~ N(0, (f s_m /
// Z)^2) at each end and l ~ N(0, s_l^2) common to the edge. `shift_px` (optional, by edge) adds
// a fixed offset (a latched edge). Edges with fewer than 3 points are left out.
inline std::vector<EdgeObservation> Observe(const std::vector<Segment3>& edges,
                                            const CameraIntrinsics& camera,
                                            const Eigen::Isometry3d& cam_from_world,
                                            const SceneNoise& noise, std::mt19937* random,
                                            const std::vector<double>& shift_px = {}) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<EdgeObservation> out;
  for (size_t k = 0; k < edges.size(); ++k) {
    Segment3 clipped = edges[k];
    if (!ClipToFrustum(cam_from_world, camera, 0.05, &clipped)) continue;
    const Eigen::Vector3d a = cam_from_world * clipped.a, b = cam_from_world * clipped.b;
    const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
    const double length = (pb - pa).norm();
    const Eigen::Vector2d d = (pb - pa) / length;
    const Eigen::Vector2d n(-d.y(), d.x());
    const double focal = 0.5 * (camera.px + camera.py);
    const double offset_a = focal * noise.model_m / a.z() * normal(*random);
    const double offset_b = focal * noise.model_m / b.z() * normal(*random);
    const double latch =
        noise.latch_px * normal(*random) + (k < shift_px.size() ? shift_px[k] : 0.0);
    EdgeObservation o{clipped.a, clipped.b, {}, static_cast<int>(k)};
    for (double s = noise.end_margin_px; s <= length - noise.end_margin_px;
         s += noise.sample_step_px) {
      const double t = s / length;
      const double shift =
          noise.point_px * normal(*random) + (1.0 - t) * offset_a + t * offset_b + latch;
      o.points.push_back(pa + s * d + shift * n);
    }
    if (o.points.size() >= 3) out.push_back(std::move(o));
  }
  return out;
}

// A camera whose focal lengths and principal point are drawn around `nominal`.
inline CameraIntrinsics DrawCamera(const CameraIntrinsics& nominal, const SceneNoise& noise,
                                   std::mt19937* random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  CameraIntrinsics camera = nominal;
  const double scale = 1.0 + noise.focal_relative * normal(*random);
  camera.px *= scale;
  camera.py *= scale;
  camera.u0 += noise.principal_point_px * normal(*random);
  camera.v0 += noise.principal_point_px * normal(*random);
  return camera;
}

// The true camera pose of a robot whose height, tilt and roll are drawn around `nominal`'s (roll
// a turn about the optical axis, as the solver's consider model has it).
inline Eigen::Isometry3d DrawRobotCamera(const RobotPose& nominal, const SceneNoise& noise,
                                         std::mt19937* random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  RobotPose pose = nominal;
  pose.height += noise.height_m * normal(*random);
  pose.tilt += noise.tilt_rad * normal(*random);
  const Eigen::Isometry3d level = CamFromWorld(pose);
  WorldTwist roll = WorldTwist::Zero();
  roll.tail<3>() = noise.roll_rad * normal(*random) * level.linear().row(2).transpose();
  return ApplyWorldTwist(level, roll);
}

}  // namespace integrity_test
}  // namespace linetrack

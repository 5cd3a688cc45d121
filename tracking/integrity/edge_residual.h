// The measurement of a tracked pose: the signed distance of a sub-pixel edge point to the image
// of its model edge, with its derivatives with respect to the pose and to the parameters the
// solve holds fixed (intrinsics; a robot's height, tilt and roll). docs/integrity.md, section 1.
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "models/camera.h"
#include "tracking/tracker/edge_refinement.h"

namespace linetrack {

// Pose perturbations live in the world frame: (dC, omega) moves the camera centre by dC (metres)
// and turns the camera by the rotation vector omega (radians, world axes), world_from_cam
// rotation R' = exp([omega]x) R.
using WorldTwist = Eigen::Matrix<double, 6, 1>;

// The residual of one edge point and its derivatives. Camera parameters: the focal scale s (px,
// py times s, derivative at s = 1) and the principal point (u0, v0), pixels.
struct EdgePointResidual {
  double residual = 0.0;                 // pixels, signed like the refinement's
  Eigen::Vector3d d_normal;              // d residual / d n (the plane normal below)
  Eigen::Matrix<double, 1, 6> d_twist;   // d residual / d (dC, omega)
  Eigen::Matrix<double, 1, 3> d_camera;  // d residual / d (s, u0, v0)
};

// The image line of the model edge A B (world) under cam_from_world, for many points:
// r = n'm / |(n_1 / px, n_2 / py)| with n = R ((A - C) x (B - C)) the normal of the plane through
// the camera centre and the edge (camera frame) and m = ((u - u0) / px, (v - v0) / py, 1), the
// pixel distance of an undistorted point to the projected line.
class EdgeLineProjection {
 public:
  EdgeLineProjection(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                     const Eigen::Isometry3d& cam_from_world, const CameraIntrinsics& camera);

  EdgePointResidual At(const Eigen::Vector2d& point) const;
  // d n / d (dC, omega) = [R [B - A]x, R [N_w]x] (R' = R exp(-[omega]x)).
  const Eigen::Matrix<double, 3, 6>& NormalOfTwist() const { return normal_of_twist_; }

 private:
  Eigen::Vector3d normal_;
  Eigen::Matrix<double, 3, 6> normal_of_twist_;
  double px_, py_, u0_, v0_;
  double rho_;  // |(n_1 / px, n_2 / py)|
};

// EdgeLineProjection(a, b, cam_from_world, camera).At(point).
EdgePointResidual LinearisePointOnEdge(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Isometry3d& cam_from_world,
                                       const CameraIntrinsics& camera,
                                       const Eigen::Vector2d& point);

// The cross-product matrix [v]x: [v]x u = v x u.
Eigen::Matrix3d CrossProductMatrix(const Eigen::Vector3d& v);

// cam_from_world moved by a world twist (dC, omega): C' = C + dC, R'_wc = exp([omega]x) R_wc.
Eigen::Isometry3d ApplyWorldTwist(const Eigen::Isometry3d& cam_from_world, const WorldTwist& twist);

// The world twist from `reference` to `pose`: (C - C_ref, log(R_wc R_wc,ref')), the inverse of
// ApplyWorldTwist (rotation angle below pi).
WorldTwist WorldTwistBetween(const Eigen::Isometry3d& reference, const Eigen::Isometry3d& pose);

// The unknowns of the pose. A robot (known height, tilt and roll): x = (x, y, heading),
// metres and radians, heading as in method.md. A free camera: x = (C, omega) in the world frame,
// 6 unknowns. `considered` are what the solve holds fixed but is uncertain: (s, u0, v0) and, for
// a robot, (height, tilt, roll).
class PoseParameterisation {
 public:
  PoseParameterisation() = default;  // a free camera
  explicit PoseParameterisation(const std::optional<KnownHeightTilt>& known) : known_(known) {}

  bool robot() const { return known_.has_value(); }
  const std::optional<KnownHeightTilt>& known() const { return known_; }
  int dof() const { return robot() ? 3 : 6; }
  int considered() const { return robot() ? 6 : 3; }

  // The pose moved by `delta` (dof() values). A robot's result has the known height, tilt and
  // roll whatever `pose` has.
  Eigen::Isometry3d Apply(const Eigen::Isometry3d& pose, const Eigen::VectorXd& delta) const;

  // The unknowns' difference estimate - truth (heading wrapped; rotation as a world vector).
  Eigen::VectorXd Difference(const Eigen::Isometry3d& estimate,
                             const Eigen::Isometry3d& truth) const;

  // d (dC, omega) / d x at `pose`: 6 x dof(). Robot: x -> dC_x, y -> dC_y, heading -> omega_z.
  Eigen::MatrixXd TwistOfUnknowns() const;

  // A robot's d (dC, omega) / d (height, tilt, roll) at `pose` (6 x 3): height -> dC_z, tilt ->
  // omega = -r (the unrolled camera's x axis, horizontal), roll -> omega = f (optical axis); a
  // free camera's is 6 x 0.
  Eigen::MatrixXd TwistOfRobotParameters(const Eigen::Isometry3d& pose) const;

 private:
  std::optional<KnownHeightTilt> known_;
};

}  // namespace linetrack

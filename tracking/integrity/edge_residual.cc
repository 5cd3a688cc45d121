#include "tracking/integrity/edge_residual.h"

#include "models/robot_pose.h"

namespace linetrack {

namespace {

Eigen::Matrix3d RotationOfVector(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

}  // namespace

Eigen::Matrix3d CrossProductMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return s;
}

EdgeLineProjection::EdgeLineProjection(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Isometry3d& cam_from_world,
                                       const CameraIntrinsics& camera)
    : px_(camera.px), py_(camera.py), u0_(camera.u0), v0_(camera.v0) {
  const Eigen::Matrix3d rotation = cam_from_world.linear();
  const Eigen::Vector3d centre = -rotation.transpose() * cam_from_world.translation();
  const Eigen::Vector3d normal_world = (a - centre).cross(b - centre);
  normal_ = rotation * normal_world;
  rho_ = std::hypot(normal_.x() / px_, normal_.y() / py_);
  // N_w = A x B + C x (A - B): d N_w / d C = [B - A]x; n = R N_w with R' = R exp(-[omega]x).
  normal_of_twist_.leftCols<3>() = rotation * CrossProductMatrix(b - a);
  normal_of_twist_.rightCols<3>() = rotation * CrossProductMatrix(normal_world);
}

EdgePointResidual EdgeLineProjection::At(const Eigen::Vector2d& point) const {
  const Eigen::Vector3d m((point.x() - u0_) / px_, (point.y() - v0_) / py_, 1.0);
  const double nu = normal_.x() / px_, nv = normal_.y() / py_;
  EdgePointResidual out;
  out.residual = normal_.dot(m) / rho_;
  // d r / d n = (m - r (n_1 / px^2, n_2 / py^2, 0) / rho) / rho.
  out.d_normal = (m - out.residual * Eigen::Vector3d(nu / px_, nv / py_, 0.0) / rho_) / rho_;
  out.d_twist = out.d_normal.transpose() * normal_of_twist_;
  // r = (n_1 m_1 + n_2 m_2 + s n_3) / rho at focal scale s; u0, v0 enter m.
  out.d_camera << normal_.z() / rho_, -nu / rho_, -nv / rho_;
  return out;
}

EdgePointResidual LinearisePointOnEdge(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                       const Eigen::Isometry3d& cam_from_world,
                                       const CameraIntrinsics& camera,
                                       const Eigen::Vector2d& point) {
  return EdgeLineProjection(a, b, cam_from_world, camera).At(point);
}

Eigen::Isometry3d ApplyWorldTwist(const Eigen::Isometry3d& cam_from_world,
                                  const WorldTwist& twist) {
  const Eigen::Matrix3d world_from_cam = cam_from_world.linear().transpose();
  const Eigen::Vector3d centre = -world_from_cam * cam_from_world.translation();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = (RotationOfVector(twist.tail<3>()) * world_from_cam).transpose();
  out.translation() = -out.linear() * (centre + twist.head<3>());
  return out;
}

WorldTwist WorldTwistBetween(const Eigen::Isometry3d& reference, const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d turn = pose.linear().transpose() * reference.linear();
  const Eigen::AngleAxisd angle_axis(turn);
  WorldTwist twist;
  twist.head<3>() = pose.inverse().translation() - reference.inverse().translation();
  twist.tail<3>() = angle_axis.angle() * angle_axis.axis();
  return twist;
}

Eigen::Isometry3d PoseParameterisation::Apply(const Eigen::Isometry3d& pose,
                                              const Eigen::VectorXd& delta) const {
  if (!known_) return ApplyWorldTwist(pose, delta);
  const RobotPose robot = RobotPoseFromCamFromWorld(pose);
  return CamFromWorld(RobotPose{robot.x + delta[0], robot.y + delta[1], robot.heading + delta[2],
                                known_->height, known_->tilt, known_->roll});
}

Eigen::VectorXd PoseParameterisation::Difference(const Eigen::Isometry3d& estimate,
                                                 const Eigen::Isometry3d& truth) const {
  if (!known_) return WorldTwistBetween(truth, estimate);
  const RobotPose e = RobotPoseFromCamFromWorld(estimate);
  const RobotPose t = RobotPoseFromCamFromWorld(truth);
  return Eigen::Vector3d(e.x - t.x, e.y - t.y, WrapAngle(e.heading - t.heading));
}

Eigen::MatrixXd PoseParameterisation::TwistOfUnknowns() const {
  if (!known_) return Eigen::MatrixXd::Identity(6, 6);
  Eigen::MatrixXd map = Eigen::MatrixXd::Zero(6, 3);
  map(0, 0) = 1.0;  // x
  map(1, 1) = 1.0;  // y
  map(5, 2) = 1.0;  // heading: a turn about world z
  return map;
}

Eigen::MatrixXd PoseParameterisation::TwistOfRobotParameters(const Eigen::Isometry3d& pose) const {
  if (!known_) return Eigen::MatrixXd::Zero(6, 0);
  // R_wc = CamFromWorldRotation(h, t)^T Rz(roll): the tilt turns it about the unrolled camera's
  // (horizontal) x axis r, the roll about f.
  const RobotPose robot = RobotPoseFromCamFromWorld(pose);
  const Eigen::Matrix3d rotation = CamFromWorldRotation(robot.heading, robot.tilt);
  Eigen::MatrixXd map = Eigen::MatrixXd::Zero(6, 3);
  map(2, 0) = 1.0;                                       // height
  map.block<3, 1>(3, 1) = -rotation.row(0).transpose();  // tilt: about -r
  map.block<3, 1>(3, 2) = rotation.row(2).transpose();   // roll: about f
  return map;
}

}  // namespace linetrack

#include "tracking/integrity/ros_covariance.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "tracking/integrity/edge_residual.h"

namespace linetrack {

Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  return {std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0))};
}

Eigen::Matrix<double, 6, 6> RosBaseCovariance(const Eigen::Matrix<double, 6, 6>& twist_covariance,
                                              const Eigen::Isometry3d& cam_from_world,
                                              const Eigen::Isometry3d& base_from_cam) {
  const Eigen::Isometry3d world_from_cam = cam_from_world.inverse();
  const Eigen::Isometry3d world_from_base = world_from_cam * base_from_cam.inverse();
  const Eigen::Vector3d lever = world_from_cam.linear() * base_from_cam.inverse().translation();
  const Eigen::Vector3d angles = RollPitchYaw(world_from_base.linear());
  const Eigen::Matrix3d yaw = Eigen::AngleAxisd(angles.z(), Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d pitch = Eigen::AngleAxisd(angles.y(), Eigen::Vector3d::UnitY()).matrix();
  Eigen::Matrix3d euler_rate;
  euler_rate.col(0) = yaw * pitch * Eigen::Vector3d::UnitX();
  euler_rate.col(1) = yaw * Eigen::Vector3d::UnitY();
  euler_rate.col(2) = Eigen::Vector3d::UnitZ();
  Eigen::Matrix<double, 6, 6> map = Eigen::Matrix<double, 6, 6>::Zero();
  map.topLeftCorner<3, 3>().setIdentity();
  map.topRightCorner<3, 3>() = -CrossProductMatrix(lever);
  map.bottomRightCorner<3, 3>() = euler_rate.inverse();
  return map * twist_covariance * map.transpose();
}

}  // namespace linetrack

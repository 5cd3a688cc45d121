#include "app/ros/ros_geometry.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "models/geometry.h"
#include "tracking/integrity/ros_covariance.h"

namespace linetrack::app {
bool CameraMount::Check(std::string* why) const {
  if (!std::isfinite(height) || !std::isfinite(pan) || !std::isfinite(tilt)) {
    *why = "camera mount: height, pan and tilt must be finite";
    return false;
  }
  if (std::abs(tilt) >= DegToRad(89.0)) {
    *why = "camera mount: tilt must be within +-89 degrees";
    return false;
  }
  return true;
}

Eigen::Isometry3d BaseFromCamera(const CameraMount& mount) {
  Eigen::Isometry3d base_from_cam = Eigen::Isometry3d::Identity();
  base_from_cam.linear() = CamFromWorldRotation(mount.pan, mount.tilt).transpose();
  base_from_cam.translation() = Eigen::Vector3d(0.0, 0.0, mount.height);
  return base_from_cam;
}

Eigen::Isometry3d PlanarIsometry(const Pose3Dof& pose) {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = Eigen::AngleAxisd(pose.heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  iso.translation() = Eigen::Vector3d(pose.x, pose.y, 0.0);
  return iso;
}

Pose3Dof PlanarOf(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d x_axis = pose.linear().col(0);
  return {pose.translation().x(), pose.translation().y(), std::atan2(x_axis.y(), x_axis.x())};
}

RobotPose CameraPrior(const Pose3Dof& map_base, const CameraMount& mount) {
  // The optical centre is above the base's origin: same x, y.
  return RobotPose{map_base.x, map_base.y, WrapAngle(map_base.heading + mount.pan), mount.height,
                   mount.tilt};
}

Eigen::Isometry3d MapFromBase(const Eigen::Isometry3d& cam_from_map, const CameraMount& mount) {
  return cam_from_map.inverse() * BaseFromCamera(mount).inverse();
}

Eigen::Isometry3d MapFromOdom(const Eigen::Isometry3d& map_from_base,
                              const Eigen::Isometry3d& odom_from_base) {
  return map_from_base * odom_from_base.inverse();
}

std::optional<Matrix6d> RosCovarianceOf(const PoseUncertainty& uncertainty,
                                        const Eigen::Isometry3d& cam_from_map,
                                        const CameraMount& mount) {
  if (!uncertainty.has_covariance()) return std::nullopt;
  const Matrix6d c =
      RosBaseCovariance(uncertainty.world_covariance, cam_from_map, BaseFromCamera(mount));
  if (!c.allFinite()) return std::nullopt;
  return Matrix6d(0.5 * (c + c.transpose()));
}

std::optional<Eigen::Isometry3d> OdometryAt(const std::vector<StampedOdometry>& readings, double t,
                                            double max_gap) {
  if (readings.empty()) return std::nullopt;
  if (t <= readings.front().t) {
    if (readings.front().t - t > max_gap) return std::nullopt;
    return readings.front().odom_from_base;
  }
  if (t >= readings.back().t) {
    if (t - readings.back().t > max_gap) return std::nullopt;
    return readings.back().odom_from_base;
  }
  const auto after = std::upper_bound(
      readings.begin(), readings.end(), t,
      [](double time, const StampedOdometry& reading) { return time < reading.t; });
  const StampedOdometry& a = *(after - 1);
  const StampedOdometry& b = *after;
  const double s = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() =
      (1.0 - s) * a.odom_from_base.translation() + s * b.odom_from_base.translation();
  const Eigen::Quaterniond qa(a.odom_from_base.linear()), qb(b.odom_from_base.linear());
  pose.linear() = qa.slerp(s, qb).toRotationMatrix();
  return pose;
}

SearchBounds BoundsFromCovariance(const Matrix6d& covariance, const RelocalizationOptions& limits,
                                  double sigma_scale) {
  const Eigen::Matrix2d xy = covariance.topLeftCorner<2, 2>();
  const double position_variance =
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(xy).eigenvalues().maxCoeff());
  const double yaw_variance = std::max(0.0, covariance(5, 5));
  SearchBounds bounds;
  bounds.delta_t = std::clamp(sigma_scale * std::sqrt(position_variance), limits.after_loss.delta_t,
                              limits.max.delta_t);
  bounds.delta_phi = std::clamp(sigma_scale * std::sqrt(yaw_variance), limits.after_loss.delta_phi,
                                limits.max.delta_phi);
  return bounds;
}

}  // namespace linetrack::app

#include "app/ros/ros_geometry.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "models/geometry.h"
#include "tracking/head/head_pointing.h"
#include "tracking/integrity/ros_covariance.h"

namespace linetrack::app {
bool CameraMount::Check(std::string* why) const {
  if (!std::isfinite(height) || !std::isfinite(pan) || !std::isfinite(tilt) || !std::isfinite(x) ||
      !std::isfinite(y) || !std::isfinite(roll)) {
    *why = "camera mount: its position and angles must be finite";
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
  base_from_cam.linear() = CamFromWorldRotation(mount.pan, mount.tilt).transpose() *
                           Eigen::AngleAxisd(mount.roll, Eigen::Vector3d::UnitZ());
  base_from_cam.translation() = Eigen::Vector3d(mount.x, mount.y, mount.height);
  return base_from_cam;
}

CameraMount MountOfBaseFromCamera(const Eigen::Isometry3d& base_from_cam) {
  const Eigen::Vector3d f = base_from_cam.linear().col(2);
  const Eigen::Vector3d image_x = base_from_cam.linear().col(0);
  CameraMount mount;
  mount.pan = std::atan2(f.y(), f.x());
  mount.tilt = -std::asin(std::clamp(f.z(), -1.0, 1.0));
  // The level frame of the optical axis: rows r (image x) and d (image y) at zero roll.
  const Eigen::Matrix3d level = CamFromWorldRotation(mount.pan, mount.tilt);
  mount.roll = std::atan2(image_x.dot(level.row(1)), image_x.dot(level.row(0)));
  mount.x = base_from_cam.translation().x();
  mount.y = base_from_cam.translation().y();
  mount.height = base_from_cam.translation().z();
  return mount;
}

CameraMount MountOnHead(const HeadGeometry& geometry, double crossing_height, double pan,
                        double tilt) {
  // The camera's pose with the base at the world's origin: the world is then the base frame, and
  // CamFromWorld(pose)^-1 has the rotation CamFromWorldRotation(heading, tilt)^T Rz(roll) of
  // BaseFromCamera, so the fields carry over one to one.
  const RobotPose camera = CameraPoseOnHead(geometry, Pose3Dof{}, crossing_height, pan, tilt);
  return CameraMount{camera.height, camera.heading, camera.tilt, camera.x, camera.y, camera.roll};
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
  const Eigen::Vector2d centre =
      Eigen::Vector2d(map_base.x, map_base.y) +
      Eigen::Rotation2Dd(map_base.heading) * Eigen::Vector2d(mount.x, mount.y);
  return RobotPose{centre.x(),   centre.y(), WrapAngle(map_base.heading + mount.pan),
                   mount.height, mount.tilt, mount.roll};
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

namespace {

// The readings a <= b around time t (sorted by .t) and s = (t - a.t) / (b.t - a.t): b = a and
// s = 0 before the first or after the last reading, when it is within max_gap of t; nullopt
// otherwise.
template <typename Reading>
struct Bracket {
  const Reading& a;
  const Reading& b;
  double s;
};

template <typename Reading>
std::optional<Bracket<Reading>> BracketAt(const std::vector<Reading>& readings, double t,
                                          double max_gap) {
  if (readings.empty()) return std::nullopt;
  if (t <= readings.front().t || t >= readings.back().t) {
    const Reading& end = t <= readings.front().t ? readings.front() : readings.back();
    if (std::abs(end.t - t) > max_gap) return std::nullopt;
    return Bracket<Reading>{end, end, 0.0};
  }
  const auto after = std::upper_bound(readings.begin(), readings.end(), t,
                                      [](double time, const Reading& r) { return time < r.t; });
  const Reading& a = *(after - 1);
  const Reading& b = *after;
  return Bracket<Reading>{a, b, b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0};
}

}  // namespace

std::optional<Eigen::Isometry3d> OdometryAt(const std::vector<StampedOdometry>& readings, double t,
                                            double max_gap) {
  const auto bracket = BracketAt(readings, t, max_gap);
  if (!bracket) return std::nullopt;
  if (&bracket->a == &bracket->b) return bracket->a.odom_from_base;  // at an end
  const Eigen::Isometry3d& a = bracket->a.odom_from_base;
  const Eigen::Isometry3d& b = bracket->b.odom_from_base;
  const double s = bracket->s;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = (1.0 - s) * a.translation() + s * b.translation();
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  pose.linear() = qa.slerp(s, qb).toRotationMatrix();
  return pose;
}

std::optional<StampedHeadAngles> HeadAnglesAt(const std::vector<StampedHeadAngles>& readings,
                                              double t, double max_gap) {
  const auto bracket = BracketAt(readings, t, max_gap);
  if (!bracket) return std::nullopt;
  const StampedHeadAngles& a = bracket->a;
  const StampedHeadAngles& b = bracket->b;
  const double s = bracket->s;
  return StampedHeadAngles{t, a.pan + s * (b.pan - a.pan), a.tilt + s * (b.tilt - a.tilt)};
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

#include "tracking/head/head_pointing.h"

#include <cmath>

#include "models/geometry.h"

namespace linetrack {

Eigen::Isometry3d WorldFromHeadBase(const Pose3Dof& base, double crossing_height) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(base.heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(base.x, base.y, crossing_height);
  return pose;
}

double CrossingHeightFor(const HeadGeometry& geometry, double camera_height) {
  return camera_height - geometry.camera_offset.z();
}

Eigen::Isometry3d CamFromWorldOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                                     double crossing_height, double pan, double tilt) {
  return (WorldFromHeadBase(base, crossing_height) * BaseFromCamera(geometry, pan, tilt)).inverse();
}

RobotPose CameraPoseOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                           double crossing_height, double pan, double tilt) {
  const Eigen::Vector3d centre =
      (WorldFromHeadBase(base, crossing_height) * BaseFromCamera(geometry, pan, tilt))
          .translation();
  return {centre.x(), centre.y(), WrapAngle(base.heading + pan), centre.z(), tilt};
}

bool HeadAnglesLookingAt(const HeadGeometry& geometry, const Eigen::Isometry3d& world_from_base,
                         const Eigen::Vector3d& target, double* pan, double* tilt) {
  const Eigen::Vector3d& offset = geometry.camera_offset;
  if (offset.x() != 0.0) return false;
  const Eigen::Vector3d p = world_from_base.inverse() * target;
  // Pan: the target's coordinate across the panned x axis equals the camera's lateral offset:
  // r sin(alpha - pan) = offset_y.
  const double r = std::hypot(p.x(), p.y());
  if (!(r > std::abs(offset.y()))) return false;
  const double alpha = std::atan2(p.y(), p.x());
  *pan = WrapAngle(alpha - std::asin(offset.y() / r));
  const double c = std::cos(*pan), s = std::sin(*pan);
  const double forward = c * p.x() + s * p.y();  // p'_x, > 0 by the choice of the asin branch
  // Tilt: rho sin(tilt + beta) = offset_z with (p'_x, p'_z) = rho (cos beta, sin beta).
  const double rho = std::hypot(forward, p.z());
  if (!(rho > std::abs(offset.z()))) return false;
  *tilt = std::asin(offset.z() / rho) - std::atan2(p.z(), forward);
  return true;
}

}  // namespace linetrack

#include "tracking/head/head_pointing.h"

#include <algorithm>
#include <cmath>

#include "models/geometry.h"
#include "models/pan_tilt.h"

namespace linetrack {
namespace {

constexpr int kMaxNewtonSteps = 50;
constexpr double kOnAxisTolerance = 1e-12;  // normalised image units
constexpr double kMaxNewtonStep = 0.5;      // radians per step, either joint

// The aligned camera's angles for a target p (base frame) with the camera centre at `offset`
// (tilt frame, its x ignored); false when the target is too close to the axes.
bool AlignedCameraAngles(const Eigen::Vector3d& offset, const Eigen::Vector3d& p, double* pan,
                         double* tilt) {
  // Pan: the target's coordinate across the panned x axis equals the camera's lateral offset:
  // r sin(alpha - pan) = offset_y.
  const double r = std::hypot(p.x(), p.y());
  if (!(r > std::abs(offset.y()))) return false;
  const double alpha = std::atan2(p.y(), p.x());
  *pan = WrapAngle(alpha - std::asin(offset.y() / r));
  const double forward = std::cos(*pan) * p.x() + std::sin(*pan) * p.y();  // p'_x > 0
  // Tilt: rho sin(tilt + beta) = offset_z with (p'_x, p'_z) = rho (cos beta, sin beta).
  const double rho = std::hypot(forward, p.z());
  if (!(rho > std::abs(offset.z()))) return false;
  *tilt = std::asin(offset.z() / rho) - std::atan2(p.z(), forward);
  return true;
}

// The target's normalised image coordinates (x/z, y/z) at (pan, tilt) and their derivatives with
// respect to (pan, tilt); false when the target is not in front of the camera.
bool ImageOfTarget(const Eigen::Isometry3d& tilt_from_camera, const Eigen::Vector3d& p, double pan,
                   double tilt, Eigen::Vector2d* f, Eigen::Matrix2d* jacobian) {
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d ry = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d panned = rz.transpose() * p;  // the target in the panned frame
  const Eigen::Vector3d in_tilt = ry.transpose() * panned;
  const Eigen::Matrix3d camera_from_tilt = tilt_from_camera.linear().transpose();
  const Eigen::Vector3d q = camera_from_tilt * (in_tilt - tilt_from_camera.translation());
  if (!(q.z() > 0.0)) return false;
  // R(a + e)^T = (I - e [axis]x) R(a)^T for a rotation about a fixed axis.
  const Eigen::Vector3d dq_dpan =
      camera_from_tilt * (ry.transpose() * -Eigen::Vector3d::UnitZ().cross(panned));
  const Eigen::Vector3d dq_dtilt = camera_from_tilt * -Eigen::Vector3d::UnitY().cross(in_tilt);
  Eigen::Matrix<double, 2, 3> d_image;
  d_image << 1.0 / q.z(), 0.0, -q.x() / (q.z() * q.z()), 0.0, 1.0 / q.z(), -q.y() / (q.z() * q.z());
  *f = Eigen::Vector2d(q.x() / q.z(), q.y() / q.z());
  jacobian->col(0) = d_image * dq_dpan;
  jacobian->col(1) = d_image * dq_dtilt;
  return true;
}

}  // namespace

Eigen::Isometry3d WorldFromHeadBase(const HeadGeometry& geometry, const Pose3Dof& base,
                                    double crossing_height) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(base.heading, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                  geometry.level_from_base;
  pose.translation() = Eigen::Vector3d(base.x, base.y, crossing_height);
  return pose;
}

double CrossingHeightFor(const HeadGeometry& geometry, double camera_height) {
  return camera_height - (geometry.level_from_base * geometry.tilt_from_camera.translation()).z();
}

Eigen::Isometry3d CamFromWorldOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                                     double crossing_height, double pan, double tilt) {
  return (WorldFromHeadBase(geometry, base, crossing_height) * BaseFromCamera(geometry, pan, tilt))
      .inverse();
}

RobotPose CameraPoseOnHead(const HeadGeometry& geometry, const Pose3Dof& base,
                           double crossing_height, double pan, double tilt) {
  return RobotPoseFromCamFromWorld(CamFromWorldOnHead(geometry, base, crossing_height, pan, tilt));
}

bool HeadAnglesLookingAt(const HeadGeometry& geometry, const Eigen::Isometry3d& world_from_base,
                         const Eigen::Vector3d& target, double* pan, double* tilt) {
  const Eigen::Vector3d p = world_from_base.inverse() * target;
  const Eigen::Isometry3d& mount = geometry.tilt_from_camera;
  double q_pan = 0.0, q_tilt = 0.0;
  if (!AlignedCameraAngles(mount.translation(), p, &q_pan, &q_tilt)) return false;
  // The optical axis' own pan and tilt on the tilting part, taken off the aligned angles.
  const Eigen::Vector3d axis = mount.linear().col(2);
  q_pan -= std::atan2(axis.y(), axis.x());
  q_tilt -= std::asin(std::clamp(-axis.z(), -1.0, 1.0));
  Eigen::Vector2d f;
  Eigen::Matrix2d jacobian;
  for (int step = 0; step <= kMaxNewtonSteps; ++step) {
    if (!ImageOfTarget(mount, p, q_pan, q_tilt, &f, &jacobian)) return false;
    if (f.lpNorm<Eigen::Infinity>() < kOnAxisTolerance) {
      *pan = WrapAngle(q_pan);
      *tilt = q_tilt;
      return true;
    }
    const Eigen::Vector2d delta = jacobian.fullPivLu().solve(-f);
    if (!delta.allFinite()) return false;
    const double scale = std::min(1.0, kMaxNewtonStep / delta.lpNorm<Eigen::Infinity>());
    q_pan += scale * delta.x();
    q_tilt += scale * delta.y();
  }
  return false;
}

}  // namespace linetrack

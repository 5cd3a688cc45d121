#include "matching/heading/vanishing_geometry.h"

#include <Eigen/Geometry>
#include <cmath>

namespace linetrack {

Eigen::Vector3d InterpretationNormal(const CameraIntrinsics& camera, const Segment2& segment) {
  return camera.Ray(segment.a).cross(camera.Ray(segment.b)).normalized();
}

Eigen::Vector2d ImageDirectionToward(const CameraIntrinsics& camera, const Eigen::Vector2d& uv,
                                     const Eigen::Vector3d& d) {
  const Eigen::Vector3d ray = camera.Ray(uv);
  return {camera.px * (d.x() - ray.x() * d.z()), camera.py * (d.y() - ray.y() * d.z())};
}

double VanishingResidual(const CameraIntrinsics& camera, const Segment2& segment,
                         const Eigen::Vector3d& d) {
  const Eigen::Vector2d g = ImageDirectionToward(camera, segment.Mid(), d);
  Eigen::Vector2d e = segment.b - segment.a;
  if (g.norm() < 1e-12 * camera.px * d.norm() || e.norm() == 0.0) return kPi / 2.0;
  if (e.dot(g) < 0.0) e = -e;
  return std::atan2(Cross2(g, e), g.dot(e));
}

Eigen::Vector3d DownInCamera(double tilt) {
  return {0.0, std::cos(tilt), std::sin(tilt)};
}

double TiltMakingHorizontal(const Eigen::Vector3d& v) {
  // v_y cos t + v_z sin t = 0  <=>  tan t = -v_y / v_z.
  double t = std::atan2(-v.y(), v.z());
  if (t > kPi / 2.0) t -= kPi;
  if (t <= -kPi / 2.0) t += kPi;
  return t;
}

double HorizontalBearing(const Eigen::Vector3d& normal_level) {
  return WrapPositive(std::atan2(-normal_level.z(), normal_level.x()), kPi);
}

double HeadingFromBearing(double theta, double alpha) {
  return WrapPositive(theta + alpha, kPi);
}

std::optional<Eigen::Vector2d> VanishingPixel(const CameraIntrinsics& camera,
                                              const Eigen::Vector3d& d) {
  if (std::abs(d.z()) < 1e-9 * d.norm()) return std::nullopt;
  return camera.Project(d.z() > 0.0 ? d : Eigen::Vector3d(-d));
}

double WrapPositive(double angle, double period) {
  double a = std::fmod(angle, period);
  if (a < 0.0) a += period;
  return a >= period ? 0.0 : a;
}

double WrapCentred(double angle, double period) {
  return WrapPositive(angle + period / 2.0, period) - period / 2.0;
}

}  // namespace linetrack

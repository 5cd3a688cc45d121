// Small value types for the project's own geometry (metres, radians, pixels).
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace linetrack {

constexpr double kPi = 3.14159265358979323846;

inline double DegToRad(double deg) {
  return deg * kPi / 180.0;
}
inline double RadToDeg(double rad) {
  return rad * 180.0 / kPi;
}

// Wraps an angle to (-pi, pi].
inline double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

// A 2D segment in pixels (u = column, v = row) or in the floor plane (x, y metres).
struct Segment2 {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();

  double Length() const { return (b - a).norm(); }
  Eigen::Vector2d Mid() const { return 0.5 * (a + b); }
};

// A 3D segment in world coordinates (metres, z up).
struct Segment3 {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();

  double Length() const { return (b - a).norm(); }
  Eigen::Vector3d Direction() const { return (b - a).normalized(); }
};

// 2D cross product (z of the 3D cross product); > 0 when b is counter-clockwise from a.
inline double Cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Clips the image segment `s` (pixels) to the rectangle [0, width - 1] x [0, height - 1] (the
// image as ClipToFrustum sees it; Liang-Barsky); false when nothing is left.
bool ClipSegmentToImage(double width, double height, Segment2* s);

}  // namespace linetrack

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

// The diamond angle of the direction (x, y): in [0, 4), strictly increasing with its bearing
// atan2(y, x) taken in [0, 2 pi): 1 - x / (|x| + |y|) for y >= 0, 3 + x / (|x| + |y|) for y < 0
// (0 along +x, 1 along +y, 2 along -x, 3 along -y; opposite directions differ by 2). 0 for (0, 0).
inline double DiamondAngle(double x, double y) {
  const double l1 = std::abs(x) + std::abs(y);
  if (l1 == 0.0) return 0.0;
  if (y >= 0.0) return 1.0 - x / l1;
  const double d = 3.0 + x / l1;
  return d < 4.0 ? d : 0.0;  // x / l1 rounded to 1: the direction is +x
}
inline double DiamondAngle(const Eigen::Vector2d& v) {
  return DiamondAngle(v.x(), v.y());
}
// The bearing (radians, in [0, 2 pi)) of the diamond angle d (any real, taken modulo 4).
double DiamondToBearing(double d);
// The diamond angle of the bearing (radians, any real): DiamondAngle(cos b, sin b).
double BearingToDiamond(double bearing);
// d modulo 4, in [0, 4): the counter-clockwise diamond distance when d is a difference.
inline double WrapDiamond(double d) {
  if (d >= 0.0 && d < 4.0) return d;
  if (d < 0.0 && d >= -4.0) return d + 4.0 < 4.0 ? d + 4.0 : 0.0;  // d + 4 may round up to 4
  const double w = d - 4.0 * std::floor(0.25 * d);
  return w < 4.0 ? w : 0.0;
}
// True when the arcs of diamond angles [a, a + a_width] and [b, b + b_width] (modulo 4, widths in
// [0, 4)) share a direction or come within `slack` of each other: one holds the other's start.
bool DiamondArcsMeet(double a, double a_width, double b, double b_width, double slack);

// Clips the image segment `s` (pixels) to the rectangle [0, width - 1] x [0, height - 1] (the
// image as ClipToFrustum sees it; Liang-Barsky); false when nothing is left.
bool ClipSegmentToImage(double width, double height, Segment2* s);

}  // namespace linetrack

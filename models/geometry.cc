#include "models/geometry.h"

#include <algorithm>
#include <cmath>

namespace linetrack {

double DiamondToBearing(double d) {
  d = WrapDiamond(d);
  // On y >= 0, x / l1 = 1 - d and |y| / l1 = 1 - |x| / l1; on y < 0, x / l1 = d - 3.
  const double c = d <= 2.0 ? 1.0 - d : d - 3.0;
  const double s = d <= 2.0 ? 1.0 - std::abs(c) : std::abs(c) - 1.0;
  const double b = std::atan2(s, c);
  return b < 0.0 ? b + 2.0 * kPi : b;
}

double BearingToDiamond(double bearing) {
  return DiamondAngle(std::cos(bearing), std::sin(bearing));
}

bool DiamondArcsMeet(double a, double a_width, double b, double b_width, double slack) {
  return WrapDiamond(b - a) <= a_width + slack || WrapDiamond(a - b) <= b_width + slack;
}

bool ClipSegmentToImage(double width, double height, Segment2* s) {
  const Eigen::Vector2d a = s->a, d = s->b - s->a;
  // Liang-Barsky: p t <= q for each side of [0, width - 1] x [0, height - 1].
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a.x(), width - 1.0 - a.x(), a.y(), height - 1.0 - a.y()};
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0.0) {
      if (q[k] < 0.0) return false;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0.0) t0 = std::max(t0, t);
    if (p[k] > 0.0) t1 = std::min(t1, t);
    if (t0 > t1) return false;
  }
  // Clamp the rounding of a + t d (~1e-13 px) so that the ends are inside the image.
  const Eigen::Vector2d box(width - 1.0, height - 1.0);
  s->a = (a + t0 * d).cwiseMax(0.0).cwiseMin(box);
  s->b = (a + t1 * d).cwiseMax(0.0).cwiseMin(box);
  return true;
}

}  // namespace linetrack

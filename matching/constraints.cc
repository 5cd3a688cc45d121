#include "matching/constraints.h"

#include <algorithm>
#include <cmath>

namespace linetrack {
namespace {

// Intersects [j.lo, j.hi] shifted by multiples of 2 pi with `prior`; appends the overlaps to
// out[*count] (room for 3 more).
void IntersectModulo(const HeadingInterval& j, const HeadingInterval& prior, HeadingInterval* out,
                     int* count) {
  const double shift = std::round((prior.Mid() - j.Mid()) / (2.0 * kPi));
  for (int k = -1; k <= 1; ++k) {
    const double s = 2.0 * kPi * (shift + k);
    const double lo = std::max(j.lo + s, prior.lo), hi = std::min(j.hi + s, prior.hi);
    if (lo <= hi) out[(*count)++] = {lo, hi};
  }
}

// Merges overlapping intervals in place (insertion sort by lo: equal lo merge alike in any
// order); returns how many are left.
int MergeInPlace(HeadingInterval* v, int count) {
  for (int i = 1; i < count; ++i) {
    for (int k = i; k > 0 && v[k].lo < v[k - 1].lo; --k)
      std::swap(v[k], v[k - 1]);
  }
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    if (kept > 0 && v[i].lo <= v[kept - 1].hi) {
      v[kept - 1].hi = std::max(v[kept - 1].hi, v[i].hi);
    } else {
      v[kept++] = v[i];
    }
  }
  return kept;
}

}  // namespace

std::vector<MatchEdge> PrepareEdges(const WireframeModel& model, const std::vector<int>& ids) {
  std::vector<MatchEdge> out;
  out.reserve(ids.size());
  for (int id : ids) {
    const ModelEdge& e = model.edges().at(id);
    MatchEdge m;
    m.edge_id = id;
    m.a = e.segment.a;
    m.b = e.segment.b;
    m.dir = (m.b - m.a).normalized();
    m.mid = 0.5 * (m.a + m.b);
    m.vertical = e.vertical;
    m.foot = m.mid.head<2>();
    out.push_back(m);
  }
  return out;
}

Eigen::Matrix3d LevelFromWorld(double heading) {
  const double ch = std::cos(heading), sh = std::sin(heading);
  Eigen::Matrix3d r;
  r << sh, -ch, 0.0, 0.0, 0.0, -1.0, ch, sh, 0.0;
  return r;
}

Eigen::Vector3d DirectionCoefficients(const Eigen::Vector3d& n, const Eigen::Vector3d& v) {
  return {n.z() * v.x() - n.x() * v.y(), n.x() * v.x() + n.z() * v.y(), -n.y() * v.z()};
}

std::vector<double> DirectionRoots(const Eigen::Vector3d& normal, const Eigen::Vector3d& v) {
  const Eigen::Vector3d abc = DirectionCoefficients(normal, v);
  const double rho = std::sqrt(abc.x() * abc.x() + abc.y() * abc.y());
  if (rho < 1e-15 || std::abs(abc.z()) > rho) return {};
  const double alpha = std::atan2(abc.y(), abc.x());
  const double theta = std::acos(std::clamp(-abc.z() / rho, -1.0, 1.0));
  if (theta == 0.0) return {WrapAngle(alpha)};
  return {WrapAngle(alpha + theta), WrapAngle(alpha - theta)};
}

std::vector<HeadingInterval> DirectionIntervals(const ObservedLine& line, const Eigen::Vector3d& v,
                                                const HeadingInterval& prior, double sigmas) {
  HeadingInterval parts[kMaxDirectionIntervals];
  const int count = DirectionIntervals(line, v, prior, sigmas, parts);
  return std::vector<HeadingInterval>(parts, parts + count);
}

int DirectionIntervals(const ObservedLine& line, const Eigen::Vector3d& v,
                       const HeadingInterval& prior, double sigmas, HeadingInterval* out) {
  const Eigen::Vector3d abc = DirectionCoefficients(line.normal, v);
  const double tolerance =
      sigmas * std::sqrt(FormVariance(line, LevelFromWorld(prior.Mid()) * v)) + 1e-12;
  const double rho = std::sqrt(abc.x() * abc.x() + abc.y() * abc.y());
  if (rho < 1e-12) {  // g1 does not depend on h (vertical edge): all or nothing
    if (std::abs(abc.z()) > tolerance) return 0;
    out[0] = prior;
    return 1;
  }
  // rho cos(h - alpha) in [-c - tol, -c + tol].
  const double lo = (-abc.z() - tolerance) / rho, hi = (-abc.z() + tolerance) / rho;
  if (hi < -1.0 || lo > 1.0) return 0;
  const double alpha = std::atan2(abc.y(), abc.x());
  const double t_near = std::acos(std::min(hi, 1.0)), t_far = std::acos(std::max(lo, -1.0));
  int count = 0;
  IntersectModulo({alpha + t_near, alpha + t_far}, prior, out, &count);
  IntersectModulo({alpha - t_far, alpha - t_near}, prior, out, &count);
  return MergeInPlace(out, count);
}

Eigen::Vector3d PositionLine(const Eigen::Vector3d& n, const Eigen::Vector3d& p, double height,
                             double heading) {
  return PositionLine(n, p, height, std::cos(heading), std::sin(heading));
}

Eigen::Vector3d PositionLine(const Eigen::Vector3d& n, const Eigen::Vector3d& p, double height,
                             double ch, double sh) {
  return PositionLines(n, p, height).At(ch, sh);
}

double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, double heading, double sigmas) {
  return PositionBandHalfWidth(line, p, camera,
                               Eigen::Vector2d(std::cos(heading), std::sin(heading)), sigmas);
}

double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, const Eigen::Vector2d& trig,
                             double sigmas) {
  return PositionBandHalfWidth(line, p, camera, trig, sigmas,
                               PositionLine(line.normal, p, camera.z(), trig.x(), trig.y()));
}

double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, const Eigen::Vector2d& trig,
                             double sigmas, const Eigen::Vector3d& l) {
  const double ch = trig.x(), sh = trig.y();
  // Rl(h) (p - C), Rl(h) with rows (sin h, -cos h, 0), (0, 0, -1), (cos h, sin h, 0).
  const Eigen::Vector3d d = p - camera;
  const Eigen::Vector3d w(sh * d.x() - ch * d.y(), -d.z(), ch * d.x() + sh * d.y());
  const double ab = std::sqrt(l.x() * l.x() + l.y() * l.y());
  if (ab < 1e-12) return std::numeric_limits<double>::infinity();
  return sigmas * std::sqrt(FormVariance(line, w)) / ab;
}

double DistanceToLine(const Eigen::Vector3d& l, const Eigen::Vector2d& q) {
  return std::abs(l.x() * q.x() + l.y() * q.y() + l.z()) / std::sqrt(l.x() * l.x() + l.y() * l.y());
}

// The point of the edge's line seen along the segment's middle ray from camera position `at`
// at heading h: closest point of the edge line to that viewing ray.
Eigen::Vector3d ObservedPointOnEdge(const ObservedLine& line, const MatchEdge& edge, double height,
                                    double heading, const Eigen::Vector2d& at) {
  return ObservedPointOnEdge(line, edge, height, std::cos(heading), std::sin(heading), at);
}

Eigen::Vector3d ObservedPointOnEdge(const ObservedLine& line, const MatchEdge& edge, double height,
                                    double ch, double sh, const Eigen::Vector2d& at) {
  const Eigen::Vector3d eye(at.x(), at.y(), height);
  // World direction of the level-frame ray m: Rl(h)^T m.
  const Eigen::Vector3d m = line.ray_a + line.ray_b;
  const Eigen::Vector3d ray(sh * m.x() + ch * m.z(), -ch * m.x() + sh * m.z(), -m.y());
  // Closest points of eye + s ray and edge.mid + t dir.
  const Eigen::Vector3d w0 = eye - edge.mid;
  const double a = ray.dot(ray), b = ray.dot(edge.dir), c = 1.0;
  const double d = ray.dot(w0), e = edge.dir.dot(w0);
  const double denom = a * c - b * b;
  if (denom < 1e-12) return edge.mid;
  const double t = (a * e - b * d) / denom;
  const double half = 0.5 * (edge.b - edge.a).norm();
  return edge.mid + std::clamp(t, -half, half) * edge.dir;
}

namespace {

// Narrows [lo, hi] to where alpha + beta s >= 0; false when nothing is left.
bool KeepNonNegative(double alpha, double beta, double* lo, double* hi) {
  if (std::abs(beta) < 1e-15) return alpha >= 0.0 && *lo <= *hi;
  const double root = -alpha / beta;
  if (beta > 0.0) {
    *lo = std::max(*lo, root);
  } else {
    *hi = std::min(*hi, root);
  }
  return *lo <= *hi;
}

}  // namespace

bool ExtentFeasible(const ObservedLine& line, const MatchEdge& edge, const PriorRegion& prior,
                    double heading, double band, const Gate& gate) {
  const double height = prior.height, radius = prior.radius;
  const Eigen::Vector2d& centre = prior.centre;
  const double slack_px = gate.extent_slack_px, focal_px = gate.focal_px;
  const Eigen::Vector3d p = ObservedPointOnEdge(line, edge, height, heading, centre);
  const Eigen::Vector3d l = PositionLine(line.normal, p, height, heading);
  const double ab = std::sqrt(l.x() * l.x() + l.y() * l.y());
  if (ab < 1e-12) return true;
  const Eigen::Vector2d n(l.x() / ab, l.y() / ab);
  const double offset = n.dot(centre) + l.z() / ab;
  const double reach = radius + band;
  if (std::abs(offset) > reach) return false;
  double lo = -std::sqrt(reach * reach - offset * offset), hi = -lo;
  const Eigen::Vector2d foot = centre - offset * n;
  const Eigen::Vector3d origin(foot.x(), foot.y(), height), along(-n.y(), n.x(), 0.0);
  const Eigen::Matrix3d world_from_level = LevelFromWorld(heading).transpose();
  const double length = (edge.b - edge.a).norm();
  for (const Eigen::Vector3d& ray : {line.ray_a, line.ray_b}) {
    const Eigen::Vector3d d = world_from_level * ray;
    const Eigen::Vector3d ed = edge.dir.cross(d);
    const double ed2 = ed.squaredNorm();
    if (ed2 < 1e-12) continue;  // the ray runs along the edge: no extent information
    // mu(s) = ((C(s) - a) x d) . (e x d) / |e x d|^2; lambda(s) = ((a - C(s)) x e) . (d x e) / |d x
    // e|^2.
    auto mu = [&](const Eigen::Vector3d& c) { return (c - edge.a).cross(d).dot(ed) / ed2; };
    auto lambda = [&](const Eigen::Vector3d& c) {
      return (edge.a - c).cross(edge.dir).dot(-ed) / ed2;
    };
    const double mu0 = mu(origin), mu1 = mu(origin + along) - mu0;
    const double la0 = lambda(origin), la1 = lambda(origin + along) - la0;
    // Tolerance along the edge for slack_px in the image: (slack / f) * depth / sin(angle).
    const double k = slack_px / focal_px / std::sqrt(ed2);
    if (!KeepNonNegative(la0 - 0.05, la1, &lo, &hi) ||
        !KeepNonNegative(mu0 + k * la0, mu1 + k * la1, &lo, &hi) ||
        !KeepNonNegative(length - mu0 + k * la0, -mu1 + k * la1, &lo, &hi)) {
      return false;
    }
  }
  return true;
}

bool VerticalExtentFeasible(const ObservedLine& line, const MatchEdge& edge,
                            const PriorRegion& prior, const Gate& gate) {
  const double height = prior.height, radius = prior.radius;
  const Eigen::Vector2d& centre = prior.centre;
  const double slack_px = gate.extent_slack_px, focal_px = gate.focal_px;
  const double distance = (edge.foot - centre).norm();
  double lo = std::max(0.05, distance - radius), hi = distance + radius;
  if (lo > hi) return false;
  const double z_lo = std::min(edge.a.z(), edge.b.z()) - height;
  const double z_hi = std::max(edge.a.z(), edge.b.z()) - height;
  for (const Eigen::Vector3d& ray : {line.ray_a, line.ray_b}) {
    const double horizontal = std::sqrt(ray.x() * ray.x() + ray.z() * ray.z());
    if (horizontal < 1e-9) continue;
    const double t = -ray.y() / horizontal;  // tan(elevation), level y points down
    const double tau = slack_px / focal_px * (1.0 + t * t);
    // z_lo <= D (t + tau) and D (t - tau) <= z_hi.
    if (!KeepNonNegative(-z_lo, t + tau, &lo, &hi) ||
        !KeepNonNegative(z_hi, -(t - tau), &lo, &hi)) {
      return false;
    }
  }
  return true;
}

std::vector<HeadingInterval> UnaryNonVertical(const ObservedLine& line, const MatchEdge& edge,
                                              const PriorRegion& prior, const Gate& gate) {
  const double sigmas = gate.sigmas;
  const double height = prior.height, radius = prior.radius;
  const Eigen::Vector2d& centre = prior.centre;
  const Eigen::Vector3d camera(centre.x(), centre.y(), height);
  std::vector<HeadingInterval> out;
  for (const HeadingInterval& j : DirectionIntervals(line, edge.dir, prior.heading, sigmas)) {
    // Signed distance of the disk centre to the position line at headings across the interval:
    // a sign change means a crossing; else the smallest distance must be within the disk radius
    // plus the noise band.
    double smallest = std::numeric_limits<double>::infinity();
    double band = 0.0;
    int sign = 0;
    bool crosses = false;
    // Samples at most 1 degree apart: the line's offset is not monotonic over wide intervals.
    const int steps = std::max(2, static_cast<int>(std::ceil(j.Width() / DegToRad(1.0))));
    for (int k = 0; k <= steps; ++k) {
      const double h = j.lo + j.Width() * k / steps;
      const Eigen::Vector3d p = ObservedPointOnEdge(line, edge, height, h, centre);
      const Eigen::Vector3d l = PositionLine(line.normal, p, height, h);
      const double s = (l.x() * centre.x() + l.y() * centre.y() + l.z()) /
                       std::sqrt(l.x() * l.x() + l.y() * l.y());
      const int sg = s > 0.0 ? 1 : -1;
      crosses = crosses || (sign != 0 && sg != sign);
      sign = sg;
      smallest = std::min(smallest, std::abs(s));
      band = std::max(band, PositionBandHalfWidth(line, p, camera, h, sigmas));
    }
    // The extent is checked at the exact root of the direction constraint when the interval
    // holds one (the interval may be clipped by the prior, so its middle can be off), and at
    // the interval's ends: with noise the heading is only known within the interval.
    double h_root = j.Mid();
    for (double root : DirectionRoots(line.normal, edge.dir)) {
      const double shifted = root + 2.0 * kPi * std::round((j.Mid() - root) / (2.0 * kPi));
      if (shifted >= j.lo && shifted <= j.hi) h_root = shifted;
    }
    bool extent = false;
    for (double h : {h_root, j.lo, j.hi}) {
      extent = extent || ExtentFeasible(line, edge, prior, h, band, gate);
    }
    if ((crosses || smallest <= radius + band) && extent) {
      out.push_back(j);
    }
  }
  return out;
}

std::optional<HeadingInterval> UnaryVertical(const ObservedLine& line, const MatchEdge& edge,
                                             const PriorRegion& prior, const Gate& gate) {
  const double sigmas = gate.sigmas;
  const double radius = prior.radius;
  const Eigen::Vector2d& centre = prior.centre;
  if (!VerticalExtentFeasible(line, edge, prior, gate)) return std::nullopt;
  const Eigen::Vector2d to_centre = centre - edge.foot;
  const double distance = to_centre.norm();
  if (distance <= radius) return prior.heading;
  const double gamma = std::atan2(to_centre.y(), to_centre.x());
  const double spread = std::asin(radius / distance) + sigmas * line.bearing_sigma;
  // Camera direction from the foot is (h - w) + pi; it must lie within gamma +- spread.
  const double h_mid = gamma - kPi + line.bearing;
  HeadingInterval parts[3];
  int count = 0;
  IntersectModulo({h_mid - spread, h_mid + spread}, prior.heading, parts, &count);
  if (count == 0) return std::nullopt;
  MergeInPlace(parts, count);
  return parts[0];
}

HeadingInterval InscribedAngleRange(const Eigen::Vector2d& foot1, const Eigen::Vector2d& foot2,
                                    const Eigen::Vector2d& centre, double radius) {
  const Eigen::Vector2d d = foot2 - foot1;
  const double t =
      d.squaredNorm() > 0.0 ? std::clamp((centre - foot1).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  if ((foot1 + t * d - centre).norm() <= radius) return {-kPi, kPi};
  constexpr int kSamples = 48;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  double nearest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kSamples; ++i) {
    const double a = 2.0 * kPi * i / kSamples;
    const Eigen::Vector2d c = centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector2d u = foot2 - c, v = foot1 - c;
    const double angle = std::atan2(Cross2(u, v), u.dot(v));
    lo = std::min(lo, angle);
    hi = std::max(hi, angle);
    nearest = std::min({nearest, u.norm(), v.norm()});
  }
  // |grad angle| <= 1/d1 + 1/d2 <= 2/nearest; the samples are 2 pi r / N apart on the circle.
  const double slack = (2.0 * kPi * radius / kSamples) * (2.0 / std::max(nearest, 1e-6));
  return {lo - slack, hi + slack};
}

bool BinaryVertical(const ObservedLine& line1, const ObservedLine& line2,
                    const HeadingInterval& range, double sigmas) {
  // Bearings lie in (-pi, pi]: their difference needs at most one turn added or removed.
  double expected = line2.bearing - line1.bearing;
  if (expected > kPi) expected -= 2.0 * kPi;
  if (expected <= -kPi) expected += 2.0 * kPi;
  const double tolerance = sigmas * std::sqrt(line1.bearing_sigma * line1.bearing_sigma +
                                              line2.bearing_sigma * line2.bearing_sigma);
  return expected >= range.lo - tolerance && expected <= range.hi + tolerance;
}

std::vector<Pose3Dof> MinimalPoses(const ObservedLine& line1, const MatchEdge& edge1,
                                   const ObservedLine& line2, const MatchEdge& edge2,
                                   double height) {
  std::vector<Pose3Dof> poses;
  const ObservedLine& heading_line = edge1.vertical ? line2 : line1;
  const MatchEdge& heading_edge = edge1.vertical ? edge2 : edge1;
  if (heading_edge.vertical) return poses;
  for (double h : DirectionRoots(heading_line.normal, heading_edge.dir)) {
    const Eigen::Vector3d l1 = PositionLine(line1.normal, edge1.mid, height, h);
    const Eigen::Vector3d l2 = PositionLine(line2.normal, edge2.mid, height, h);
    const double det = l1.x() * l2.y() - l1.y() * l2.x();
    const double scale =
        std::sqrt(l1.x() * l1.x() + l1.y() * l1.y()) * std::sqrt(l2.x() * l2.x() + l2.y() * l2.y());
    if (std::abs(det) < 1e-6 * scale) continue;  // parallel position lines
    const double x = (l1.y() * l2.z() - l2.y() * l1.z()) / det;
    const double y = (l2.x() * l1.z() - l1.x() * l2.z()) / det;
    poses.push_back({x, y, h});
  }
  return poses;
}

}  // namespace linetrack

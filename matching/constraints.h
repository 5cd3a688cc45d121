// The geometric constraints of the interpretation tree (Ait Aider et al. 2005, section 3.2),
// rewritten in the level frame (tilt undone) with the project's conventions. For an image line
// with level-frame interpretation-plane normal nL and a model edge with direction v through p:
//   direction (1.a):  g1(h)       = nL . Rl(h) v       = a cos h + b sin h + c = 0
//   position  (1.b):  g2(h, x, y) = nL . Rl(h) (p - C) = A x + B y + C0       = 0
// with Rl(h) the level-from-world rotation (rows (sin h, -cos h, 0), (0, 0, -1), (cos h, sin h, 0))
// and C = (x, y, z) the camera centre at the known height z.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <vector>

#include "matching/observed_line.h"
#include "models/robot_pose.h"
#include "models/wireframe.h"

namespace linetrack {

// A closed heading interval [lo, hi] (radians, lo <= hi; may extend past +-pi).
struct HeadingInterval {
  double lo = 0.0;
  double hi = 0.0;
  double Mid() const { return 0.5 * (lo + hi); }
  double Width() const { return hi - lo; }
};

// The prior the constraints test against: the disk of camera positions (centre, radius, metres)
// and the interval of headings, at the known camera height (metres).
struct PriorRegion {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius = 0.0;
  HeadingInterval heading;
  double height = 0.0;
  double focal_px = 1000.0;  // mean focal length of the camera (pixels)
  // When set, camera positions lie in this box (the navigable area's bounds).
  bool has_bounds = false;
  Eigen::Vector2d bounds_min = Eigen::Vector2d::Zero(), bounds_max = Eigen::Vector2d::Zero();
};

// Margins of the constraints: the noise gate in standard deviations, and the tolerance of the
// extent constraints at segment endpoints (pixels, for a camera of focal length focal_px).
struct Gate {
  double sigmas = 3.0;
  double extent_slack_px = 8.0;
  double focal_px = 1000.0;
};

// A model edge prepared for matching (world frame, metres).
struct MatchEdge {
  int edge_id = -1;
  Eigen::Vector3d a, b;  // endpoints
  Eigen::Vector3d dir;   // unit direction a -> b
  Eigen::Vector3d mid;   // midpoint, the reference point p of the position constraint
  bool vertical = false;
  Eigen::Vector2d foot;  // plan position (vertical edges)
};

// Prepares the listed model edges (ids into model.edges()).
std::vector<MatchEdge> PrepareEdges(const WireframeModel& model, const std::vector<int>& ids);

// Level-from-world rotation for heading h (radians).
Eigen::Matrix3d LevelFromWorld(double heading);

// Coefficients (a, b, c) of the direction constraint g1(h) = a cos h + b sin h + c:
// a = nL_z v_x - nL_x v_y, b = nL_x v_x + nL_z v_y, c = -nL_y v_z.
Eigen::Vector3d DirectionCoefficients(const Eigen::Vector3d& normal, const Eigen::Vector3d& v);

// Headings (radians) solving g1(h) = 0 exactly: zero, one or two roots.
std::vector<double> DirectionRoots(const Eigen::Vector3d& normal, const Eigen::Vector3d& v);

// Headings within `prior` where |g1(h)| <= sigmas * std(g1) (std at the prior's mid heading):
// up to two intervals, clipped to `prior`; empty when the correspondence is impossible.
std::vector<HeadingInterval> DirectionIntervals(const ObservedLine& line, const Eigen::Vector3d& v,
                                                const HeadingInterval& prior, double sigmas);
// The same written into `out` (room for kMaxDirectionIntervals), without allocating (the
// tree's forward checking calls it per candidate and node); returns how many.
constexpr int kMaxDirectionIntervals = 6;
int DirectionIntervals(const ObservedLine& line, const Eigen::Vector3d& v,
                       const HeadingInterval& prior, double sigmas, HeadingInterval* out);

// The position line (A, B, C0) of the camera (x, y) at heading h: A x + B y + C0 = 0, with
// A = -(nL_z cos h + nL_x sin h), B = nL_x cos h - nL_z sin h,
// C0 = cos h (nL_z p_x - nL_x p_y) + sin h (nL_x p_x + nL_z p_y) - nL_y (p_z - z).
Eigen::Vector3d PositionLine(const Eigen::Vector3d& normal, const Eigen::Vector3d& p, double height,
                             double heading);
// The same with cos h, sin h given (hot loops).
Eigen::Vector3d PositionLine(const Eigen::Vector3d& normal, const Eigen::Vector3d& p, double height,
                             double cos_h, double sin_h);
// PositionLine of one (normal, p, height) at several headings: the terms that do not depend on
// the heading computed once (the same values as PositionLine, bit for bit).
class PositionLines {
 public:
  PositionLines(const Eigen::Vector3d& normal, const Eigen::Vector3d& p, double height)
      : n_(normal),
        c_(normal.z() * p.x() - normal.x() * p.y()),
        s_(normal.x() * p.x() + normal.z() * p.y()),
        z_(normal.y() * (p.z() - height)) {}
  Eigen::Vector3d At(double cos_h, double sin_h) const {
    return {-(n_.z() * cos_h + n_.x() * sin_h), n_.x() * cos_h - n_.z() * sin_h,
            cos_h * c_ + sin_h * s_ - z_};
  }

 private:
  Eigen::Vector3d n_;
  double c_, s_, z_;
};

// Half-width (metres) of the noise band around the position line through the edge point p at
// heading h, for the camera centre `camera` (x, y, height): sigmas * std(g2) / |(A, B)|.
double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, double heading, double sigmas);
// The same with trig = (cos h, sin h) given (hot loops).
double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, const Eigen::Vector2d& trig,
                             double sigmas);
// The same with PositionLine(line.normal, p, camera.z(), cos h, sin h) given as `position_line`.
double PositionBandHalfWidth(const ObservedLine& line, const Eigen::Vector3d& p,
                             const Eigen::Vector3d& camera, const Eigen::Vector2d& trig,
                             double sigmas, const Eigen::Vector3d& position_line);

// The point of the edge (clamped to it) seen along the segment's middle ray from camera
// position `at` at heading h: the closest point of the edge's line to that viewing ray. The
// position constraint and its noise are evaluated there.
Eigen::Vector3d ObservedPointOnEdge(const ObservedLine& line, const MatchEdge& edge, double height,
                                    double heading, const Eigen::Vector2d& at);
Eigen::Vector3d ObservedPointOnEdge(const ObservedLine& line, const MatchEdge& edge, double height,
                                    double cos_h, double sin_h, const Eigen::Vector2d& at);

// Distance from `point` to the line (A, B, C0) in the plane.
double DistanceToLine(const Eigen::Vector3d& line, const Eigen::Vector2d& point);

// Extent constraint (not in the paper): the observed segment is the image of a part of the edge
// (occlusion only shortens it), in front of the camera. At heading h the camera lies on the
// position line; along it (C(s) = C0 + s u) the edge parameter mu_k(s) where endpoint ray k meets
// the edge line, and the ray depth lambda_k(s), are linear in s. True when some s on the chord
// of the prior's disk (widened by `band` metres) has 0 < lambda_k and mu_k within the edge, with
// the gate's extent_slack_px pixels of tolerance at the endpoints.
bool ExtentFeasible(const ObservedLine& line, const MatchEdge& edge, const PriorRegion& prior,
                    double heading, double band, const Gate& gate);

// Extent constraint for a vertical edge: the heights where the endpoint rays meet the edge,
// z_cam + D tan(elevation_k), must lie within the edge's z range (with the gate's
// extent_slack_px of tolerance) for some horizontal distance D from the prior's disk to the foot.
// Independent of the heading.
bool VerticalExtentFeasible(const ObservedLine& line, const MatchEdge& edge,
                            const PriorRegion& prior, const Gate& gate);

// Unary constraint for a non-vertical edge (paper, fig. 4, with noise margins): some heading in
// the prior's interval satisfies the direction constraint and its position line passes within
// the band of the prior's disk. Returns the admissible heading intervals (empty: rejected).
std::vector<HeadingInterval> UnaryNonVertical(const ObservedLine& line, const MatchEdge& edge,
                                              const PriorRegion& prior, const Gate& gate);

// Unary constraint for a vertical edge (not in the paper): the camera lies on the ray from the
// edge's foot opposite to the world bearing h - w; for h in the prior's interval these rays sweep
// a wedge that must meet the prior's disk; and the vertical extent must fit. Returns the
// admissible heading interval.
std::optional<HeadingInterval> UnaryVertical(const ObservedLine& line, const MatchEdge& edge,
                                             const PriorRegion& prior, const Gate& gate);

// Range [lo, hi] (radians) of the signed angle from the direction camera -> foot2 to the
// direction camera -> foot1, over camera positions in the disk: the inscribed angle is harmonic in
// the camera position, so its extremes lie on the boundary circle (sampled, with a slack for the
// sampling step). Returns {-pi, pi} when a foot or the segment between them meets the disk.
HeadingInterval InscribedAngleRange(const Eigen::Vector2d& foot1, const Eigen::Vector2d& foot2,
                                    const Eigen::Vector2d& centre, double radius);

// Binary constraint for two vertical correspondences (paper, fig. 6): the angle w_2 - w_1 between
// the two image lines is the inscribed angle of the feet seen from the camera, which puts the
// camera on one circle arc (the sign fixes the left-to-right order); the arc must meet the disk:
// w_2 - w_1 within `range` (InscribedAngleRange of the feet) widened by the noise.
bool BinaryVertical(const ObservedLine& line1, const ObservedLine& line2,
                    const HeadingInterval& range, double sigmas);

// Minimal poses from two correspondences at known height: the headings solving the direction
// constraint of a non-vertical one (up to two), then the position where both position lines
// cross. Empty when both edges are vertical or the lines are parallel.
std::vector<Pose3Dof> MinimalPoses(const ObservedLine& line1, const MatchEdge& edge1,
                                   const ObservedLine& line2, const MatchEdge& edge2,
                                   double height);

}  // namespace linetrack

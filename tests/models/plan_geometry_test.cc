// Floor-plan geometry under the navigable area and the VIRs: convex rings, the wall arrangement,
// full-height occluders, and the hidden/bearing tests against brute-force sampling.
#include <gtest/gtest.h>

#include <random>

#include "models/convex_polygon.h"
#include "models/plan_arrangement.h"
#include "models/plan_visibility.h"

namespace linetrack {
namespace {

constexpr double kTol = 1e-9;
constexpr double kMarginM = 1e-3;

Ring2 Box(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

TEST(ConvexRing, SplitByALineKeepsTheArea) {
  Ring2 left, right;
  ASSERT_TRUE(SplitConvex(Box(0, 0, 1, 1), {Eigen::Vector2d::UnitX(), 0.25}, 1e-12, &right, &left));
  EXPECT_NEAR(RingSignedArea(left), 0.25, kTol);
  EXPECT_NEAR(RingSignedArea(right), 0.75, kTol);
  EXPECT_FALSE(SplitConvex(Box(0, 0, 1, 1), {Eigen::Vector2d::UnitX(), 2.0}, 1e-12, &right, &left));
  EXPECT_FALSE(SplitConvex(Box(0, 0, 1, 1), {Eigen::Vector2d::UnitX(), 1.0}, 1e-12, &right, &left));
}

TEST(ConvexRing, ClipsASegment) {
  double t0 = 0.0, t1 = 0.0;
  ASSERT_TRUE(ClipSegmentToConvex(Box(0, 0, 1, 1), {{-1.0, 0.5}, {3.0, 0.5}}, &t0, &t1));
  EXPECT_NEAR(t0, 0.25, kTol);
  EXPECT_NEAR(t1, 0.5, kTol);
  EXPECT_FALSE(ClipSegmentToConvex(Box(0, 0, 1, 1), {{-1.0, 1.5}, {3.0, 1.5}}, &t0, &t1));
  EXPECT_NEAR(DistanceToConvex(Box(0, 0, 1, 1), {2.0, 0.5}), 1.0, kTol);
  EXPECT_EQ(DistanceToConvex(Box(0, 0, 1, 1), {0.3, 0.5}), 0.0);
}

TEST(ConvexRing, PiecesOfAnLShapeAreConvexAndCoverIt) {
  const Ring2 l_shape = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const std::vector<Ring2> pieces = ConvexPieces(l_shape);
  ASSERT_FALSE(pieces.empty());
  EXPECT_LE(pieces.size(), 3u);
  double area = 0.0;
  for (const Ring2& piece : pieces) {
    EXPECT_TRUE(IsConvexRing(piece));
    area += RingSignedArea(piece);
  }
  EXPECT_NEAR(area, 3.0, kTol);
}

TEST(ConvexRing, SimplifyDropsSpikesAndStraightVertices) {
  // A square with a straight-through vertex on its south side and a spike into it from the north.
  const Ring2 ring = {{0, 0}, {1, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 1}, {1, 2}, {0, 2}};
  const Ring2 simple = SimplifyRing(ring, 1e-9);
  EXPECT_EQ(simple.size(), 4u);
  EXPECT_NEAR(RingSignedArea(simple), 4.0, kTol);
}

TEST(PlanArrangement, RoomWithAPartitionHasOneInwardFacingFace) {
  // A 4 x 3 room (walls facing in) and a one-sided partition from the south wall.
  const Ring2 room = Box(0, 0, 4, 3);
  std::vector<PlanWall> walls;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = room[i], b = room[(i + 1) % 4];
    const Eigen::Vector2d d = (b - a).normalized();
    walls.push_back({{a, b}, {-d.y(), d.x()}});  // the left of a -> b is inside
  }
  walls.push_back({{{2.0, 0.0}, {2.0, 1.5}}, {1.0, 0.0}});
  const PlanArrangement arrangement = PlanArrangement::Build(walls, 1e-9);
  EXPECT_EQ(arrangement.vertices().size(), 6u);  // corners, the T junction, the partition's end
  EXPECT_EQ(arrangement.edges().size(), 6u);
  EXPECT_EQ(arrangement.num_components(), 1);
  int bounded = 0;
  for (const PlanCycle& cycle : arrangement.cycles()) {
    if (cycle.signed_area <= 0.0) continue;
    ++bounded;
    EXPECT_NEAR(cycle.signed_area, 12.0, kTol);
    EXPECT_NEAR(cycle.length, 14.0 + 3.0, kTol);  // the partition is walked on both sides
    EXPECT_NEAR(cycle.facing_length, 14.0 + 1.5, kTol);
    EXPECT_EQ(arrangement.CycleRing(cycle).size(), 4u);  // the partition is a spike, dropped
  }
  EXPECT_EQ(bounded, 1);
}

TEST(FullHeight, ADoorCutOutLeavesTheWallOnBothSides) {
  // A 3 m wide, 3 m high wall face with a 1 m wide, 2.1 m high door, as one polygon (s, z).
  const Ring2 wall = {{0, 0}, {1, 0}, {1, 2.1}, {2, 2.1}, {2, 0}, {3, 0}, {3, 3}, {0, 3}};
  const auto spans = FullHeightSpans(wall, 0.01, 2.99);
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_NEAR(spans[0].first, 0.0, kTol);
  EXPECT_NEAR(spans[0].second, 1.0, kTol);
  EXPECT_NEAR(spans[1].first, 2.0, kTol);
  EXPECT_NEAR(spans[1].second, 3.0, kTol);
  // A gable wall (a pentagon) covers the band [0, 3] only where its roof line is above 3 m.
  const Ring2 gable = {{0, 0}, {4, 0}, {4, 2}, {2, 4}, {0, 2}};
  const auto gable_spans = FullHeightSpans(gable, 0.0, 3.0);
  ASSERT_EQ(gable_spans.size(), 1u);
  EXPECT_NEAR(gable_spans[0].first, 1.0, kTol);
  EXPECT_NEAR(gable_spans[0].second, 3.0, kTol);
  EXPECT_TRUE(FullHeightSpans(Box(0, 0, 2, 1.8), 0.01, 2.49).empty());  // a cabinet side
}

TEST(PlanVisibility, MergesCollinearPieces) {
  const std::vector<Segment2> merged = MergeCollinear(
      {{{0, 0}, {1, 0}}, {{2, 0}, {1, 0}}, {{3, 0}, {4, 0}}, {{0, 1}, {1, 1}}}, 1e-9);
  EXPECT_EQ(merged.size(), 3u);  // 0..2 and 3..4 on y = 0, 0..1 on y = 1
}

TEST(PlanVisibility, WallHidesWhatIsBehindIt) {
  const Ring2 region = Box(0, 0, 1, 1);
  const Segment2 wall{{-1.0, 2.0}, {3.0, 2.0}};
  EXPECT_TRUE(HiddenByWall(region, {{0.5, 3.0}}, wall, kMarginM));
  EXPECT_TRUE(HiddenByWall(region, {{-0.5, 3.0}, {1.5, 3.0}}, wall, kMarginM));
  EXPECT_FALSE(HiddenByWall(region, {{5.0, 3.0}}, wall, kMarginM));  // seen past the wall's end
  EXPECT_FALSE(HiddenByWall(region, {{0.5, 2.0}}, wall, kMarginM));  // on the wall itself
  EXPECT_FALSE(HiddenByWall(region, {{0.5, 1.5}}, wall, kMarginM));  // in front of it
  // A region touching the wall's line, within the wall, is still on one side.
  EXPECT_TRUE(HiddenByWall(Box(0, 1, 1, 2), {{0.5, 3.0}}, wall, kMarginM));
}

// Uniform points of a convex ring (rejection from its box).
Eigen::Vector2d PointIn(const Ring2& ring, std::mt19937* rng) {
  Eigen::Vector2d lo = ring[0], hi = ring[0];
  for (const Eigen::Vector2d& p : ring)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y());
  for (;;) {
    const Eigen::Vector2d p(ux(*rng), uy(*rng));
    if (ConvexContains(ring, p)) return p;
  }
}

// A random convex ring: the hull-ordered corners of a random box rotated, around `centre`.
Ring2 RandomBox(const Eigen::Vector2d& centre, double size, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double w = size * (0.2 + unit(*rng)), h = size * (0.2 + unit(*rng));
  const double a = 2.0 * kPi * unit(*rng);
  const Eigen::Vector2d u(std::cos(a), std::sin(a)), v(-u.y(), u.x());
  return {centre - w * u - h * v, centre + w * u - h * v, centre + w * u + h * v,
          centre - w * u + h * v};
}

TEST(PlanVisibility, HiddenTestsAgreeWithSampledSightLines) {
  std::mt19937 rng(5u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hidden_by_solid = 0, hidden_by_wall = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Ring2 region = RandomBox({0.0, 0.0}, 0.5, &rng);
    const Ring2 solid = RandomBox({3.0, 4.0 * unit(rng) - 2.0}, 1.0, &rng);
    const Eigen::Vector2d f0(6.0 + 2.0 * unit(rng), 6.0 * unit(rng) - 3.0);
    const Ring2 footprint =
        trial % 2 ? Ring2{f0} : Ring2{f0, f0 + Eigen::Vector2d(unit(rng) - 0.5, unit(rng) - 0.5)};
    const Segment2 wall{solid[0], solid[2]};  // a diagonal of the solid as a thin wall
    const bool by_solid = HiddenBySolid(region, footprint, solid, kMarginM);
    const bool by_wall = HiddenByWall(region, footprint, wall, kMarginM);
    hidden_by_solid += by_solid;
    hidden_by_wall += by_wall;
    if (!by_solid && !by_wall) continue;
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d p = k < 4 ? region[k] : PointIn(region, &rng);
      const Eigen::Vector2d q = footprint.size() == 1
                                    ? footprint[0]
                                    : footprint[0] + unit(rng) * (footprint[1] - footprint[0]);
      double t0 = 0.0, t1 = 0.0;
      if (by_solid) {
        ASSERT_TRUE(ClipSegmentToConvex(solid, {p, q}, &t0, &t1) && (t1 - t0) > 0.0)
            << "trial " << trial << ": a sight line misses the solid";
      }
      if (by_wall) {
        // p and q strictly on opposite sides of the wall, crossing it between its ends.
        const Line2 line = Line2::Through(wall.a, wall.b);
        const double sp = line.SignedDistance(p), sq = line.SignedDistance(q);
        ASSERT_LT(sp * sq, 0.0) << "trial " << trial;
        const Eigen::Vector2d x = p + sp / (sp - sq) * (q - p);
        const double along = (x - wall.a).dot(wall.b - wall.a) / (wall.b - wall.a).squaredNorm();
        ASSERT_TRUE(along >= 0.0 && along <= 1.0) << "trial " << trial << ": misses the wall";
      }
    }
  }
  EXPECT_GT(hidden_by_solid, 100);  // the configurations do exercise both outcomes
  EXPECT_LT(hidden_by_solid, 2900);
  EXPECT_GT(hidden_by_wall, 10);
}

// True when the sight line p -> q crosses the segment `wall` (strictly between its sides).
bool Crosses(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Segment2& wall) {
  const Line2 line = Line2::Through(wall.a, wall.b);
  const double sp = line.SignedDistance(p), sq = line.SignedDistance(q);
  if (!(sp * sq < 0.0)) return false;
  const Eigen::Vector2d x = p + sp / (sp - sq) * (q - p);
  const double along = (x - wall.a).dot(wall.b - wall.a) / (wall.b - wall.a).squaredNorm();
  return along >= 0.0 && along <= 1.0;
}

TEST(PlanVisibility, CornerHidesWhatNeitherWallHidesAlone) {
  // A room's corner at (4, 4): its north wall from (1, 4), its east wall from (4, 0). A point far
  // to the north-east seen past the corner from inside the room.
  const Ring2 eyes = Box(1.0, 1.0, 3.5, 3.5);
  const Eigen::Vector2d corner(4.0, 4.0), north(1.0, 4.0), east(4.0, 0.0);
  const Ring2 far = {{12.0, 6.0}};
  EXPECT_FALSE(HiddenByWall(eyes, far, {north, corner}, kMarginM));
  EXPECT_FALSE(HiddenByWall(eyes, far, {east, corner}, kMarginM));
  EXPECT_TRUE(HiddenByCorner(eyes, far, corner, north, east, kMarginM));
  EXPECT_TRUE(HiddenByCorner(eyes, far, corner, east, north, kMarginM));
  // A point to the north, past the corner too; with a door in the north wall (the wall starts at
  // x = 2.5), seen through it.
  const Ring2 north_far = {{6.0, 12.0}};
  EXPECT_TRUE(HiddenByCorner(eyes, north_far, corner, north, east, kMarginM));
  EXPECT_FALSE(HiddenByCorner(eyes, north_far, corner, {2.5, 4.0}, east, kMarginM));
  // In front of the north wall's line: not behind the corner.
  EXPECT_FALSE(HiddenByCorner(eyes, {{12.0, 3.9}}, corner, north, east, kMarginM));
  // The same walls seen from outside the room (the corner reflex): no claim.
  EXPECT_FALSE(
      HiddenByCorner(Box(5.0, 5.0, 6.0, 6.0), {{2.0, 2.0}}, corner, north, east, kMarginM));
}

TEST(PlanVisibility, CornerTestAgreesWithSampledSightLines) {
  std::mt19937 rng(7u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hidden = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // Two walls from a corner near the origin at an angle of 30-150 degrees, eyes on one side.
    const Eigen::Vector2d corner(unit(rng) - 0.5, unit(rng) - 0.5);
    const double a = 2.0 * kPi * unit(rng), b = a + DegToRad(30.0 + 120.0 * unit(rng));
    const Eigen::Vector2d far_a =
        corner + (1.0 + 3.0 * unit(rng)) * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Eigen::Vector2d far_b =
        corner + (1.0 + 3.0 * unit(rng)) * Eigen::Vector2d(std::cos(b), std::sin(b));
    const Eigen::Vector2d inside = corner + 0.5 * (far_a - corner) + 0.5 * (far_b - corner);
    const Ring2 eyes =
        RandomBox(inside + 0.5 * Eigen::Vector2d(unit(rng) - 0.5, unit(rng) - 0.5), 0.4, &rng);
    const Eigen::Vector2d f0 = corner + 4.0 * (corner - inside).normalized() +
                               3.0 * Eigen::Vector2d(unit(rng) - 0.5, unit(rng) - 0.5);
    const Ring2 footprint =
        trial % 2 ? Ring2{f0} : Ring2{f0, f0 + Eigen::Vector2d(unit(rng) - 0.5, unit(rng) - 0.5)};
    if (!HiddenByCorner(eyes, footprint, corner, far_a, far_b, kMarginM)) continue;
    ++hidden;
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d p = k < 4 ? eyes[k] : PointIn(eyes, &rng);
      const Eigen::Vector2d q = footprint.size() == 1
                                    ? footprint[0]
                                    : footprint[0] + unit(rng) * (footprint[1] - footprint[0]);
      ASSERT_TRUE(Crosses(p, q, {far_a, corner}) || Crosses(p, q, {far_b, corner}))
          << "trial " << trial << ": a sight line passes the corner";
    }
  }
  EXPECT_GT(hidden, 100);  // the configurations do exercise both outcomes
  EXPECT_LT(hidden, 2900);
}

TEST(PlanVisibility, WallCornersPairTheWallsThatMeet) {
  // An L of two walls, a third collinear with the first, and one apart.
  const std::vector<Segment2> walls = {{{0.0, 0.0}, {2.0, 0.0}},
                                       {{2.0, 0.0}, {2.0, 3.0}},
                                       {{2.0, 0.0}, {5.0, 0.0}},
                                       {{9.0, 9.0}, {9.0, 8.0}}};
  const std::vector<std::vector<WallCorner>> corners = WallCorners(walls, 1e-6);
  ASSERT_EQ(corners.size(), 4u);
  ASSERT_EQ(corners[0].size(), 1u);  // the collinear one makes no corner
  EXPECT_EQ(corners[0][0].corner, Eigen::Vector2d(2.0, 0.0));
  EXPECT_EQ(corners[0][0].far_self, Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(corners[0][0].far_other, Eigen::Vector2d(2.0, 3.0));
  EXPECT_EQ(corners[1].size(), 2u);
  EXPECT_EQ(corners[2].size(), 1u);
  EXPECT_TRUE(corners[3].empty());
}

TEST(ConvexRing, ClipAndHullOfBoxes) {
  const Ring2 half = ClipConvex(Box(0, 0, 2, 2), {Eigen::Vector2d::UnitX(), 0.5});
  EXPECT_NEAR(RingSignedArea(half), 3.0, kTol);
  EXPECT_TRUE(ClipConvex(Box(0, 0, 2, 2), {Eigen::Vector2d::UnitX(), 3.0}).empty());
  Ring2 points = Box(0, 0, 1, 1), hull;
  const Ring2 other = Box(2, 0, 3, 1);
  points.insert(points.end(), other.begin(), other.end());
  points.push_back({1.5, 0.5});  // inside the hull
  ConvexHull(&points, &hull);
  EXPECT_EQ(hull.size(), 4u);
  EXPECT_NEAR(RingSignedArea(hull), 3.0, kTol);
}

TEST(PlanVisibility, BearingRangeHoldsEverySampledBearingAndIsTight) {
  std::mt19937 rng(9u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    const Ring2 region = RandomBox({0.0, 0.0}, 0.5, &rng);
    const double a = 2.0 * kPi * unit(rng);
    const Eigen::Vector2d f0 = (1.5 + 3.0 * unit(rng)) * Eigen::Vector2d(std::cos(a), std::sin(a));
    const Ring2 footprint = {f0,
                             f0 + Eigen::Vector2d(2.0 * unit(rng) - 1.0, 2.0 * unit(rng) - 1.0)};
    const BearingRange range = BearingsToFootprint(region, footprint);
    if (range.all) continue;
    EXPECT_GE(range.min, 0.0);
    EXPECT_LT(range.min, 4.0);
    EXPECT_GE(range.max, range.min);
    EXPECT_LT(range.max - range.min, 2.0);
    // The diamond arc as bearings (radians): [lo, lo + width].
    const double lo = DiamondToBearing(range.min);
    double width = DiamondToBearing(range.max) - lo;
    width -= 2.0 * kPi * std::floor(width / (2.0 * kPi));
    if (width > 1.5 * kPi) width = 0.0;  // a zero-width arc whose end rounded below its start
    EXPECT_LT(width, kPi);
    double widest = 0.0;
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector2d v =
          footprint[0] + unit(rng) * (footprint[1] - footprint[0]) - PointIn(region, &rng);
      const double b = std::atan2(v.y(), v.x());
      const double from_min = b - lo - 2.0 * kPi * std::floor((b - lo) / (2.0 * kPi));
      EXPECT_LE(from_min, width + kTol) << "trial " << trial;
      widest = std::max(widest, from_min);
    }
    EXPECT_GT(widest, 0.8 * width);  // not needlessly wide
  }
  // A footprint touching the region is seen under every bearing.
  EXPECT_TRUE(BearingsToFootprint(Box(0, 0, 1, 1), {{1.0, 0.5}, {2.0, 0.5}}).all);
  EXPECT_TRUE(BearingsToFootprint(Box(0, 0, 1, 1), {{0.5, 0.5}}).all);
}

// Every point of the footprint seen from a point of the disk under a bearing of the arc lies in
// the clipped part, which is part of the footprint.
TEST(PlanVisibility, BearingWedgeKeepsEveryPointSeenUnderTheArc) {
  std::mt19937 rng(31u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int seen = 0, clipped = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Vector2d centre(4.0 * unit(rng) - 2.0, 4.0 * unit(rng) - 2.0);
    const double radius = 0.1 + unit(rng), heading = 2.0 * kPi * unit(rng);
    const double half = 1.6 * unit(rng);
    const Segment2 footprint{{10.0 * unit(rng) - 5.0, 10.0 * unit(rng) - 5.0},
                             {10.0 * unit(rng) - 5.0, 10.0 * unit(rng) - 5.0}};
    Segment2 part;
    const bool any = ClipToBearingWedge(footprint, centre, radius, heading, half, &part);
    if (any) {
      EXPECT_LT(DistanceToSegment(part.a, footprint), kTol);
      EXPECT_LT(DistanceToSegment(part.b, footprint), kTol);
      clipped += part.Length() < footprint.Length() - kTol ? 1 : 0;
    }
    for (int k = 0; k < 200; ++k) {
      const double r = radius * std::sqrt(unit(rng)), a = 2.0 * kPi * unit(rng);
      const Eigen::Vector2d eye = centre + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      const Eigen::Vector2d p = footprint.a + unit(rng) * (footprint.b - footprint.a);
      const double bearing = std::atan2(p.y() - eye.y(), p.x() - eye.x());
      if (std::abs(WrapAngle(bearing - heading)) > half) continue;
      ++seen;
      ASSERT_TRUE(any) << "trial " << trial;
      EXPECT_LT(DistanceToSegment(p, part), kTol) << "trial " << trial;
    }
  }
  EXPECT_GT(seen, 1000);   // points under the arc are tested
  EXPECT_GT(clipped, 50);  // and the clip does cut footprints
}

TEST(PlanVisibility, PolygonAroundDiskHoldsTheDisk) {
  for (int sides : {3, 8, 13}) {
    const Eigen::Vector2d centre(1.5, -2.0);
    const Ring2 ring = PolygonAroundDisk(centre, 0.7, sides);
    ASSERT_EQ(ring.size(), static_cast<size_t>(sides));
    EXPECT_GT(RingSignedArea(ring), 0.0);
    for (int k = 0; k < 360; ++k) {
      const double a = DegToRad(k);
      EXPECT_TRUE(
          ConvexContains(ring, centre + 0.7 * Eigen::Vector2d(std::cos(a), std::sin(a)), 0.0))
          << sides << " sides, " << k << " deg";
    }
  }
}

}  // namespace
}  // namespace linetrack

// The linear combination of views (seed 002, eqs. 4-13) on exact weak-perspective projections:
// the coefficients, the novel view's rotation, scale and centre, and the reference depth are
// recovered to numerical precision, and the mean depth triangulated from two views; on
// perspective projections the error grows with the depth
// range over the distance, and the weak-perspective check notices.
#include "matching/views/view_combination.h"

#include <gtest/gtest.h>

#include <random>

#include "models/geometry.h"
#include "models/robot_pose.h"

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;

Eigen::Matrix3d Turn(double heading, double tilt) {
  return CamFromWorldRotation(heading, tilt) * CamFromWorldRotation(0.0, 0.0).transpose();
}

// Weak-perspective image of object points p under w.
std::vector<Eigen::Vector2d> Project(const std::vector<Eigen::Vector3d>& p,
                                     const WeakPerspective& w) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector3d& q : p)
    out.push_back(w.scale * (w.rotation.topRows<2>() * q) + w.translation);
  return out;
}

// Perspective image of camera-1-frame points X seen from (rotation, centre).
std::vector<Eigen::Vector2d> Perspective(const std::vector<Eigen::Vector3d>& x,
                                         const Eigen::Matrix3d& rotation,
                                         const Eigen::Vector3d& centre) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector3d& q : x) {
    const Eigen::Vector3d c = rotation * (q - centre);
    out.push_back(c.head<2>() / c.z());
  }
  return out;
}

std::vector<double> Xs(const std::vector<Eigen::Vector2d>& v) {
  std::vector<double> out;
  for (const Eigen::Vector2d& p : v)
    out.push_back(p.x());
  return out;
}

// Camera-1-frame points in a box of half-sizes (2, 1, depth_range / 2) around (0, 0, distance).
std::vector<Eigen::Vector3d> Scene(double distance, double depth_range, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 20; ++i) {
    out.emplace_back(2.0 * unit(rng), unit(rng), distance + 0.5 * depth_range * unit(rng));
  }
  return out;
}

TEST(ViewCombination, ExactWeakPerspectiveIsRecovered) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double z0 = 6.0;
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 12; ++i)
    p.emplace_back(0.4 * unit(rng), 0.2 * unit(rng), 0.3 * unit(rng));
  const Eigen::Matrix3d r2 = Turn(DegToRad(20.0), DegToRad(3.0));
  const Eigen::Vector3d c2(1.5, -0.1, 0.4);
  const Eigen::Matrix3d rn = Turn(DegToRad(-12.0), DegToRad(-2.0));
  const Eigen::Vector3d cn(-0.8, 0.05, -0.6);
  const auto w1 = WeakPerspectiveOf(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), z0);
  const auto w2 = WeakPerspectiveOf(r2, c2, z0);
  const auto wn = WeakPerspectiveOf(rn, cn, z0);
  ASSERT_TRUE(w1 && w2 && wn);
  EXPECT_NEAR(w1->scale, 1.0, kExactTol);
  EXPECT_NEAR(w1->translation.norm(), 0.0, kExactTol);
  const std::vector<Eigen::Vector2d> v1 = Project(p, *w1), v2 = Project(p, *w2),
                                     vn = Project(p, *wn);

  const auto combination = FitViewCombination(v1, Xs(v2), vn);
  ASSERT_TRUE(combination.has_value());
  EXPECT_NEAR(combination->rms, 0.0, kExactTol);
  const NovelView novel = RecoverNovelView(*combination, *w2, z0);
  EXPECT_NEAR(novel.scale_a, wn->scale, 1e-9);
  EXPECT_NEAR(novel.scale_b, wn->scale, 1e-9);
  EXPECT_NEAR(novel.orthogonality, 0.0, 1e-9);
  EXPECT_LT((novel.rotation - rn).norm(), 1e-9);
  EXPECT_LT((novel.centre - cn).norm(), 1e-8);
}

TEST(ViewCombination, MeanTriangulatedDepthIsTheScenesMeanDepth) {
  std::mt19937_64 rng(4);
  const std::vector<Eigen::Vector3d> x = Scene(7.0, 3.0, rng);
  const Eigen::Matrix3d r2 = Turn(DegToRad(12.0), DegToRad(-2.0));
  const Eigen::Vector3d c2(1.2, 0.1, 0.5);
  const auto depth =
      MeanTriangulatedDepth(Perspective(x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
                            Perspective(x, r2, c2), r2, c2);
  ASSERT_TRUE(depth.has_value());
  double mean = 0.0;
  for (const Eigen::Vector3d& p : x)
    mean += p.z() / x.size();
  EXPECT_NEAR(*depth, mean, 1e-9);
  // Without a baseline the rays do not meet: no depth.
  EXPECT_FALSE(MeanTriangulatedDepth(
                   Perspective(x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
                   Perspective(x, r2, Eigen::Vector3d::Zero()), r2, Eigen::Vector3d::Zero())
                   .has_value());
}

TEST(ViewCombination, DegenerateWithoutRotationBetweenTheModelViews) {
  std::mt19937_64 rng(2);
  const std::vector<Eigen::Vector3d> x = Scene(5.0, 1.0, rng);
  const std::vector<Eigen::Vector2d> v1 =
      Perspective(x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  // Model view 2 only translated: under weak perspective x2 = s x1 + t_x, in the span of x1, 1.
  std::vector<double> x2;
  for (const Eigen::Vector2d& p : v1)
    x2.push_back(0.9 * p.x() + 0.1);
  EXPECT_FALSE(FitViewCombination(v1, x2, v1).has_value());
  // Fewer than four points.
  const std::vector<Eigen::Vector2d> three(v1.begin(), v1.begin() + 3);
  EXPECT_FALSE(FitViewCombination(three, {0.1, 0.2, 0.3}, three).has_value());
}

// Position error of the recovered novel camera (metres) on perspective projections: model
// view 2 turned 15 deg about the scene's centre, the novel view turned `turn_deg` and at
// `range` x the distance from it.
double PerspectiveError(double distance, double depth_range, double turn_deg, double range,
                        NovelView* novel, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<Eigen::Vector3d> x = Scene(distance, depth_range, rng);
  // The model views and the novel one look at the scene's centre from around it.
  const Eigen::Vector3d target(0.0, 0.0, distance);
  auto camera = [&](double angle, double scale) {
    const Eigen::Matrix3d r = Turn(angle, 0.0);
    return std::make_pair(
        r, Eigen::Vector3d(target - r.transpose() * Eigen::Vector3d(0, 0, scale * distance)));
  };
  const auto [r2, c2] = camera(DegToRad(15.0), 1.0);
  const auto [rn, cn] = camera(DegToRad(turn_deg), range);
  const std::vector<Eigen::Vector2d> v1 =
      Perspective(x, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const std::vector<Eigen::Vector2d> v2 = Perspective(x, r2, c2), vn = Perspective(x, rn, cn);
  const auto z0 = MeanTriangulatedDepth(v1, v2, r2, c2);
  const auto w2 = WeakPerspectiveOf(r2, c2, *z0);
  const auto combination = FitViewCombination(v1, Xs(v2), vn);
  *novel = RecoverNovelView(*combination, *w2, *z0);
  return (novel->centre - cn).norm();
}

TEST(ViewCombination, PerspectiveErrorGrowsWithTheDepthRangeAndTheCheckSeesIt) {
  // The novel view 30 % nearer than the model views: the scene looks deeper to it.
  NovelView far, deep;
  const double far_error = PerspectiveError(20.0, 4.0, 6.0, 0.7, &far, 3);
  const double deep_error = PerspectiveError(4.0, 4.0, 6.0, 0.7, &deep, 3);
  // 4 m deep 20 m away: weak perspective holds, the error is a small share of the distance and
  // eqs. 10 and 11 agree on the scale.
  EXPECT_LT(far_error / 20.0, 0.01);
  EXPECT_LT(std::abs(far.scale_a - far.scale_b) / far.scale_a, 0.02);
  // As deep as it is far: the error is a large share of the distance, and the scales disagree
  // beyond the check's 10 %.
  EXPECT_GT(deep_error / 4.0, 0.05);
  EXPECT_GT(std::abs(deep.scale_a - deep.scale_b) / (0.5 * (deep.scale_a + deep.scale_b)), 0.1);
}

}  // namespace
}  // namespace linetrack

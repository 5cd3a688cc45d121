// The mount's covariance against Monte Carlo draws of exact synthetic views (truth known): pixel
// noise independent per coordinate plus a displacement shared by each view's points
// (calibration/view_shift.h). The normalised error e^T C^-1 e of the 6-dof mount averages its
// dimension 6 when C models the shared displacement, not when it is s^2 (J^T J)^-1; the moment
// estimates of the two variances are unbiased.
#include <gtest/gtest.h>

#include <random>

#include "calibration/mount_calibration.h"
#include "calibration/view_shift.h"
#include "tests/support/mount_scene.h"

namespace linetrack {
namespace {

using test_support::CamFromBoard;
using test_support::MakeMountScene;
using test_support::MountScene;

constexpr int kDraws = 1000;
constexpr double kNoisePx = 0.1;   // independent, per coordinate
constexpr double kShiftPx = 0.03;  // shared by a view's points, per image axis
// Mean of kDraws chi-square(6) draws: 6 +- 1.96 sqrt(12 / 1000) = 6 +- 0.21 (95 %); wider for
// the estimated variances' own noise (a little optimistic) and for tau^2 >= 0 (a little
// pessimistic when there is no shared shift).
constexpr double kNeesLow = 5.5, kNeesHigh = 6.5;
constexpr double kVarianceRelTol = 0.1;  // the mean moment estimates against the truth

struct DrawStats {
  double nees_model = 0.0, nees_plain = 0.0;  // means over the draws
  double sigma2 = 0.0, tau2 = 0.0;            // mean estimates (tau^2 from the data alone)
};

double Nees(const Eigen::Matrix<double, 6, 1>& e, const Eigen::MatrixXd& c) {
  return e.dot(c.topLeftCorner<6, 6>().ldlt().solve(e));
}

// kDraws calibrations of scene `s` from its exact projections plus the two errors.
// known_px: the shift given to the covariance (< 0: estimated from the residuals).
DrawStats RunDraws(const MountScene& s, double shift_px, double known_px, std::uint64_t seed) {
  const std::vector<Eigen::Vector3d> board = BoardPoints(s.pattern);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  DrawStats stats;
  for (int d = 0; d < kDraws; ++d) {
    std::vector<BoardView> views;
    for (const HeadAngles& a : s.angles) {
      BoardView v;
      v.board_points = board;
      const Eigen::Isometry3d pose = CamFromBoard(s.tilt_from_camera, s.base_from_board, a);
      const Eigen::Vector2d shift(shift_px * normal(rng), shift_px * normal(rng));
      for (const Eigen::Vector3d& x : board) {
        v.image_points.push_back(ProjectPoint(s.camera, pose * x, nullptr) + shift +
                                 kNoisePx * Eigen::Vector2d(normal(rng), normal(rng)));
      }
      views.push_back(v);
    }
    const PoseResiduals residuals = MountResiduals(s.camera, views, s.angles);
    std::vector<Eigen::Isometry3d> poses = {s.tilt_from_camera, s.base_from_board};
    const PoseLeastSquaresResult solved = SolvePoseLeastSquares(residuals, {}, &poses);
    EXPECT_TRUE(solved.ok) << solved.failure;
    Eigen::VectorXd r;
    Eigen::MatrixXd jacobian;
    residuals(poses, &r, &jacobian);
    const ViewShiftCovariance model = EstimateViewShiftCovariance(
        jacobian, r, std::vector<int>(views.size(), static_cast<int>(board.size())), known_px);
    EXPECT_TRUE(model.ok);
    const Eigen::Matrix<double, 6, 1> e = PoseDelta(poses[0], s.tilt_from_camera);
    stats.nees_model += Nees(e, model.covariance) / kDraws;
    stats.nees_plain += Nees(e, solved.covariance) / kDraws;
    stats.sigma2 += model.sigma_px * model.sigma_px / kDraws;
    stats.tau2 += model.tau_data_px * model.tau_data_px / kDraws;
  }
  return stats;
}

TEST(MountCovariance, ConsistentWithAKnownSharedViewShift) {
  const DrawStats stats = RunDraws(MakeMountScene(21), kShiftPx, kShiftPx, 1);
  EXPECT_GT(stats.nees_model, kNeesLow);
  EXPECT_LT(stats.nees_model, kNeesHigh);
  // The plain s^2 (J^T J)^-1 is optimistic: its NEES is far above 6.
  EXPECT_GT(stats.nees_plain, 2.0 * kNeesHigh);
}

TEST(MountCovariance, MomentEstimatesOfTheTwoVariances) {
  const DrawStats stats = RunDraws(MakeMountScene(22), kShiftPx, -1.0, 2);
  EXPECT_NEAR(stats.tau2, kShiftPx * kShiftPx, kVarianceRelTol * kShiftPx * kShiftPx);
  EXPECT_NEAR(stats.sigma2, kNoisePx * kNoisePx, kVarianceRelTol * kNoisePx * kNoisePx);
  EXPECT_GT(stats.nees_model, kNeesLow);
  EXPECT_LT(stats.nees_model, kNeesHigh);
}

TEST(MountCovariance, IndependentNoiseAloneKeepsItsNees) {
  const DrawStats stats = RunDraws(MakeMountScene(23), 0.0, -1.0, 3);
  EXPECT_GT(stats.nees_model, kNeesLow);
  EXPECT_LT(stats.nees_model, kNeesHigh);
  EXPECT_GT(stats.nees_plain, kNeesLow);
  EXPECT_LT(stats.nees_plain, kNeesHigh);
}

}  // namespace
}  // namespace linetrack

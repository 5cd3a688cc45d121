// The benchmarks' judge of one localisation (app/match_outcome.h) on cases at and around its
// bounds.
#include "app/match_outcome.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "models/geometry.h"

namespace linetrack::app {
namespace {

// Errors with no confidence region to fall back on (the fixed tolerance decides).
PoseErrors Fixed(double position_m, double heading_deg) {
  return {position_m, heading_deg, std::numeric_limits<double>::infinity()};
}

TEST(MatchOutcome, NoPoseIsNoAnswerWhateverTheRest) {
  EXPECT_EQ(JudgeMatch(false, true, Fixed(0.0, 0.0)), MatchOutcome::kNone);
  EXPECT_EQ(JudgeMatch(false, false, Fixed(9.0, 90.0)), MatchOutcome::kNone);
}

TEST(MatchOutcome, TruePairsAndAccuratePoseIsCorrect) {
  EXPECT_EQ(JudgeMatch(true, true, Fixed(0.07, 0.3)), MatchOutcome::kCorrect);
  EXPECT_EQ(JudgeMatch(true, true, Fixed(kAccuratePositionM, kAccurateHeadingDeg)),
            MatchOutcome::kCorrect);
}

TEST(MatchOutcome, TruePairsButFarPoseIsWrong) {
  // Seed 1 QI3 scene 228 before the fourth round: every reported pair true, the pose 1.3 m off.
  EXPECT_EQ(JudgeMatch(true, true, Fixed(1.3, 0.5)), MatchOutcome::kWrong);
  EXPECT_EQ(JudgeMatch(true, true, Fixed(0.1, kAccurateHeadingDeg + 0.01)), MatchOutcome::kWrong);
}

TEST(MatchOutcome, FalsePairWithAccuratePoseIsWrongButAccurate) {
  EXPECT_EQ(JudgeMatch(true, false, Fixed(0.2, 1.0)), MatchOutcome::kWrongAccurate);
  EXPECT_EQ(JudgeMatch(true, false, Fixed(0.51, 1.0)), MatchOutcome::kWrong);
}

TEST(MatchOutcome, FarPoseInsideItsOwnConfidenceRegionIsAccurate) {
  EXPECT_EQ(JudgeMatch(true, true, {0.6, 4.0, kOwnRegionChi2}), MatchOutcome::kCorrect);
  EXPECT_EQ(JudgeMatch(true, true, {0.6, 4.0, kOwnRegionChi2 + 0.01}), MatchOutcome::kWrong);
  EXPECT_EQ(JudgeMatch(true, false, {0.6, 4.0, 3.0}), MatchOutcome::kWrongAccurate);
}

TEST(MatchOutcome, ErrorsOfMeasuresTheTruthInTheAnswersCovariance) {
  // Covariance of (heading, x, y): 1 degree, 0.3 m along x, 0.1 m along y, uncorrelated.
  Eigen::Matrix3d covariance = Eigen::Vector3d(std::pow(DegToRad(1.0), 2), 0.09, 0.01).asDiagonal();
  const Pose3Dof truth{2.0, 3.0, DegToRad(179.0)};
  // 0.6 m along x (2 sigma), 0.1 m along y (1 sigma), 2 degrees across the +-180 wrap (2 sigma).
  const Pose3Dof answer{2.6, 3.1, DegToRad(-179.0)};
  const PoseErrors errors = ErrorsOf(answer, covariance, truth);
  constexpr double kTolerance = 1e-9;
  EXPECT_NEAR(errors.position_m, std::hypot(0.6, 0.1), kTolerance);
  EXPECT_NEAR(errors.heading_deg, 2.0, kTolerance);
  EXPECT_NEAR(errors.mahalanobis2, 4.0 + 1.0 + 4.0, 1e-6);
  EXPECT_EQ(JudgeMatch(true, true, errors), MatchOutcome::kCorrect);
  // A singular covariance gives no region: the fixed tolerance alone decides.
  covariance.setZero();
  EXPECT_TRUE(std::isinf(ErrorsOf(answer, covariance, truth).mahalanobis2));
  EXPECT_EQ(JudgeMatch(true, true, ErrorsOf(answer, covariance, truth)), MatchOutcome::kWrong);
}

TEST(MatchOutcome, NanErrorsAreNeverAccurate) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(JudgeMatch(true, true, {nan, 0.0, nan}), MatchOutcome::kWrong);
  EXPECT_EQ(JudgeMatch(true, true, {0.0, nan, nan}), MatchOutcome::kWrong);
}

TEST(MatchOutcome, NamesAreThoseOfTheTables) {
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kCorrect), "correct");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kNone), "no answer");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kWrongAccurate), "wrong but accurate");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kWrong), "wrong");
}

}  // namespace
}  // namespace linetrack::app

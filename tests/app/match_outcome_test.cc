// The benchmarks' judge of one localisation (app/match_outcome.h) on cases at and around its
// bounds.
#include "app/match_outcome.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace linetrack::app {
namespace {

TEST(MatchOutcome, NoPoseIsNoAnswerWhateverTheRest) {
  EXPECT_EQ(JudgeMatch(false, true, 0.0, 0.0), MatchOutcome::kNone);
  EXPECT_EQ(JudgeMatch(false, false, 9.0, 90.0), MatchOutcome::kNone);
}

TEST(MatchOutcome, TruePairsAndAccuratePoseIsCorrect) {
  EXPECT_EQ(JudgeMatch(true, true, 0.07, 0.3), MatchOutcome::kCorrect);
  EXPECT_EQ(JudgeMatch(true, true, kAccuratePositionM, kAccurateHeadingDeg),
            MatchOutcome::kCorrect);
}

TEST(MatchOutcome, TruePairsButFarPoseIsWrong) {
  // Seed 1 QI3 scene 228 before the fourth round: every reported pair true, the pose 1.3 m off.
  EXPECT_EQ(JudgeMatch(true, true, 1.3, 0.5), MatchOutcome::kWrong);
  EXPECT_EQ(JudgeMatch(true, true, 0.1, kAccurateHeadingDeg + 0.01), MatchOutcome::kWrong);
}

TEST(MatchOutcome, FalsePairWithAccuratePoseIsWrongButAccurate) {
  EXPECT_EQ(JudgeMatch(true, false, 0.2, 1.0), MatchOutcome::kWrongAccurate);
  EXPECT_EQ(JudgeMatch(true, false, 0.51, 1.0), MatchOutcome::kWrong);
}

TEST(MatchOutcome, NanErrorsAreNeverAccurate) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(JudgeMatch(true, true, nan, 0.0), MatchOutcome::kWrong);
  EXPECT_EQ(JudgeMatch(true, true, 0.0, nan), MatchOutcome::kWrong);
}

TEST(MatchOutcome, NamesAreThoseOfTheTables) {
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kCorrect), "correct");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kNone), "no answer");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kWrongAccurate), "wrong but accurate");
  EXPECT_STREQ(MatchOutcomeName(MatchOutcome::kWrong), "wrong");
}

}  // namespace
}  // namespace linetrack::app

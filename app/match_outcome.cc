#include "app/match_outcome.h"

namespace linetrack::app {

const char* MatchOutcomeName(MatchOutcome outcome) {
  switch (outcome) {
    case MatchOutcome::kCorrect:
      return "correct";
    case MatchOutcome::kNone:
      return "no answer";
    case MatchOutcome::kWrongAccurate:
      return "wrong but accurate";
    case MatchOutcome::kWrong:
      return "wrong";
  }
  return "";
}

MatchOutcome JudgeMatch(bool found, bool reported_correspondences_all_true, double position_error_m,
                        double heading_error_deg) {
  if (!found) return MatchOutcome::kNone;
  // Written so that NaN errors are never accurate.
  const bool accurate =
      position_error_m <= kAccuratePositionM && heading_error_deg <= kAccurateHeadingDeg;
  if (!accurate) return MatchOutcome::kWrong;
  return reported_correspondences_all_true ? MatchOutcome::kCorrect : MatchOutcome::kWrongAccurate;
}

}  // namespace linetrack::app

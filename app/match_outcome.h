// How the benchmarks judge one localisation against its ground truth (`bench match`,
// `bench localize-image`): the paper's Table 3 categories, with the pose checked as well.
#pragma once

namespace linetrack::app {

// A pose this close to the truth is "accurate" (metres in the ground plane, degrees of heading).
constexpr double kAccuratePositionM = 0.5;
constexpr double kAccurateHeadingDeg = 5.0;

enum class MatchOutcome { kCorrect, kNone, kWrongAccurate, kWrong };

// "correct", "no answer", "wrong but accurate", "wrong".
const char* MatchOutcomeName(MatchOutcome outcome);

// Correct: a pose with at least one reported correspondence, all of them true, and the pose
// accurate. Wrong but accurate: an accurate pose reporting a false correspondence (the paper's
// consistent false positive). Wrong: any pose that is not accurate, even when every reported
// correspondence is true (a few true pairs can leave the pose free along a weak direction).
MatchOutcome JudgeMatch(bool found, bool reported_correspondences_all_true, double position_error_m,
                        double heading_error_deg);

}  // namespace linetrack::app

// How the benchmarks judge one localisation against its ground truth (`bench match`,
// `bench localize-image`): the paper's Table 3 categories, with the pose checked as well.
#pragma once

#include <Eigen/Core>

#include <utility>
#include <vector>

#include "matching/localizer.h"
#include "models/robot_pose.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack::app {

// A pose this close to the truth is "accurate" (metres in the ground plane, degrees of heading).
constexpr double kAccuratePositionM = 0.5;
constexpr double kAccurateHeadingDeg = 5.0;
// A pose farther than that is still accurate when the truth lies inside the answer's own
// confidence region: squared Mahalanobis distance within the 99.9 % quantile of chi2(3).
constexpr double kOwnRegionChi2 = 16.27;

enum class MatchOutcome { kCorrect, kNone, kWrongAccurate, kWrong };

// "correct", "no answer", "wrong but accurate", "wrong".
const char* MatchOutcomeName(MatchOutcome outcome);

// How far an answer is from the truth: metres, degrees, and the truth's squared Mahalanobis
// distance under the answer's covariance of (heading rad, x m, y m) (infinite when that
// covariance is not positive definite or not finite).
struct PoseErrors {
  double position_m = 0.0;
  double heading_deg = 0.0;
  double mahalanobis2 = 0.0;
  // Within kAccuratePositionM and kAccurateHeadingDeg (NaN never is).
  bool WithinTolerance() const;
};
PoseErrors ErrorsOf(const Pose3Dof& answer, const Eigen::Matrix3d& covariance,
                    const Pose3Dof& truth);

// Correct: a pose with at least one reported correspondence, all of them true, and the pose
// accurate. Wrong but accurate: an accurate pose reporting a false correspondence (the paper's
// consistent false positive). Wrong: any pose that is not accurate, even when every reported
// correspondence is true (unreported pairs can hold the pose away from the truth). Accurate:
// within the fixed tolerance, or the truth inside the answer's own 99.9 % confidence region (a
// weakly observed pose that says so is not a wrong claim; one that claims more is).
MatchOutcome JudgeMatch(bool found, bool reported_correspondences_all_true,
                        const PoseErrors& errors);

// True when `reported` (model edge id, line index) pairs are not empty and all in `truth`.
bool ReportedMatchesTrue(const std::vector<std::pair<int, int>>& truth,
                         const std::vector<std::pair<int, int>>& reported);

// JudgeMatch of a localisation of a synthetic scene against the scene's ground truth.
MatchOutcome JudgeScene(const SyntheticScene& scene, const LocalizationResult& result);

}  // namespace linetrack::app

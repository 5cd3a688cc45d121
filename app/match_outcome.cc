#include "app/match_outcome.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "models/geometry.h"

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

bool PoseErrors::WithinTolerance() const {
  // Written so that NaN errors are never within.
  return position_m <= kAccuratePositionM && heading_deg <= kAccurateHeadingDeg;
}

PoseErrors ErrorsOf(const Pose3Dof& answer, const Eigen::Matrix3d& covariance,
                    const Pose3Dof& truth) {
  PoseErrors errors;
  const Eigen::Vector3d e(WrapAngle(answer.heading - truth.heading), answer.x - truth.x,
                          answer.y - truth.y);
  errors.position_m = std::hypot(e[1], e[2]);
  errors.heading_deg = RadToDeg(std::abs(e[0]));
  errors.mahalanobis2 = std::numeric_limits<double>::infinity();
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (covariance.allFinite() && llt.info() == Eigen::Success) {
    const double m2 = e.dot(llt.solve(e));
    if (std::isfinite(m2)) errors.mahalanobis2 = m2;
  }
  return errors;
}

MatchOutcome JudgeMatch(bool found, bool reported_correspondences_all_true,
                        const PoseErrors& errors) {
  if (!found) return MatchOutcome::kNone;
  const bool accurate = errors.WithinTolerance() || errors.mahalanobis2 <= kOwnRegionChi2;
  if (!accurate) return MatchOutcome::kWrong;
  return reported_correspondences_all_true ? MatchOutcome::kCorrect : MatchOutcome::kWrongAccurate;
}

bool ReportedMatchesTrue(const std::vector<std::pair<int, int>>& truth,
                         const std::vector<std::pair<int, int>>& reported) {
  const std::set<std::pair<int, int>> known(truth.begin(), truth.end());
  return !reported.empty() && std::all_of(reported.begin(), reported.end(),
                                          [&](const auto& m) { return known.count(m) > 0; });
}

MatchOutcome JudgeScene(const SyntheticScene& scene, const LocalizationResult& result) {
  return JudgeMatch(result.found, ReportedMatchesTrue(scene.matches, result.matches),
                    ErrorsOf(result.pose.Planar(), result.covariance, scene.truth.Planar()));
}

}  // namespace linetrack::app

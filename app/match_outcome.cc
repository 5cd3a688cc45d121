#include "app/match_outcome.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

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

}  // namespace linetrack::app

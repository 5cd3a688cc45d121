#include "matching/global/global_decision.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "matching/pose_decision.h"
#include "matching/pose_refinement.h"
#include "models/geometry.h"

namespace linetrack {

std::vector<Explanation> AllExplanations(const std::vector<PeakVerification>& verifications) {
  std::vector<Explanation> all;
  for (size_t i = 0; i < verifications.size(); ++i) {
    const LocalizationResult& r = verifications[i].result;
    for (size_t k = 0; k < r.finalists.size(); ++k) {
      const Finalist& f = r.finalists[k];
      all.push_back({f.pose, f.evidence.Score(), f.evidence.Support(), static_cast<int>(i),
                     r.found && k == 0});
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const Explanation& a, const Explanation& b) { return a.score > b.score; });
  return all;
}

double FamilyMargin(double ambiguity_nats, int verified_peaks) {
  return ambiguity_nats + std::log(static_cast<double>(std::max(1, verified_peaks)));
}

Eigen::Matrix3d NearSpreadCovariance(const Pose3Dof& answer, const Eigen::Matrix3d& covariance,
                                     double best_score, const std::vector<Explanation>& near) {
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  double total = 0.0;
  for (const Explanation& e : near) {
    const double w = std::exp(std::min(0.0, e.score - best_score));
    const Eigen::Vector3d d(WrapAngle(e.pose.heading - answer.heading), e.pose.x - answer.x,
                            e.pose.y - answer.y);
    spread += w * d * d.transpose();
    total += w;
  }
  return total > 0.0 ? Eigen::Matrix3d(covariance + spread / total) : covariance;
}

bool NearPose(const Pose3Dof& best, const Pose3Dof& e, const GlobalOptions& options) {
  return std::hypot(e.x - best.x, e.y - best.y) <= options.near_m &&
         std::abs(WrapAngle(e.heading - best.heading)) <= DegToRad(options.near_deg);
}

namespace {

// The distinct rivals of the best explanation (see DecideGlobal), best first.
std::vector<Pose3Dof> Rivals(const std::vector<Explanation>& all, const VerificationOptions& vo,
                             const GlobalOptions& options, int verified_peaks) {
  const Explanation& best = all.front();
  const double family = FamilyMargin(vo.ambiguity_nats, verified_peaks);
  std::vector<Pose3Dof> rivals;
  for (const Explanation& e : all) {
    if (NearPose(best.pose, e.pose, options)) continue;
    const double gap = best.score - e.score;
    const bool close = gap < vo.ambiguity_nats;
    const bool disagrees =
        e.accepted && gap < family && e.support >= options.min_support && e.support >= best.support;
    if (!close && !disagrees) continue;
    if (std::none_of(rivals.begin(), rivals.end(),
                     [&](const Pose3Dof& r) { return SamePose(r, e.pose, vo); }))
      rivals.push_back(e.pose);
  }
  return rivals;
}

// The index of the verification that accepted the best explanation (or a pose the same as it),
// -1 when none did.
int AcceptingVerification(const std::vector<Explanation>& all, const VerificationOptions& vo) {
  for (const Explanation& e : all) {
    if (e.accepted && SamePose(e.pose, all.front().pose, vo)) return e.verification;
  }
  return -1;
}

}  // namespace

void DecideGlobal(const VerificationOptions& vo, const GlobalOptions& options, GlobalResult* out) {
  const std::vector<Explanation> all = AllExplanations(out->verifications);
  if (all.empty()) {
    out->reason = "no heading candidate's search found a plausible pose";
    return;
  }
  const Explanation& best = all.front();
  const std::vector<Pose3Dof> rivals =
      Rivals(all, vo, options, static_cast<int>(out->verifications.size()));
  if (!rivals.empty()) {
    out->ambiguous = true;
    out->rivals = {best.pose};
    out->rivals.insert(out->rivals.end(), rivals.begin(), rivals.end());
    out->reason = "ambiguous: " + std::to_string(out->rivals.size()) +
                  " distinct poses explain the image almost as well";
    return;
  }
  const int accepting = AcceptingVerification(all, vo);
  if (accepting < 0) {
    out->reason = out->verifications[best.verification].result.reason;
    out->ambiguous = out->reason.rfind("ambiguous", 0) == 0;
    if (out->ambiguous) out->rivals = {best.pose};
    return;
  }
  if (best.support < options.min_support) {
    out->reason = "the best pose observes " +
                  std::to_string(static_cast<int>(100.0 * best.support)) +
                  " % of its predicted outline (a partial explanation)";
    return;
  }
  LocalizationResult answer = out->verifications[accepting].result;
  std::vector<Explanation> near;
  for (const Explanation& e : all) {
    if (best.score - e.score < vo.ambiguity_nats) near.push_back(e);
  }
  answer.covariance =
      NearSpreadCovariance(answer.pose.Planar(), answer.covariance, best.score, near);
  answer.heading_sigma_rad = std::sqrt(answer.covariance(0, 0));
  answer.position_sigma_m = LargestPositionSigma(answer.covariance.block<2, 2>(1, 1));
  if (answer.position_sigma_m > vo.max_position_sigma_m ||
      answer.heading_sigma_rad > DegToRad(vo.max_heading_sigma_deg)) {
    out->reason =
        "the poses near the best that explain the image almost as well spread beyond "
        "the observability limits";
    return;
  }
  out->found = true;
  out->best = std::move(answer);
}

}  // namespace linetrack

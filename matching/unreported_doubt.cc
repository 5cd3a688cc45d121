#include "matching/unreported_doubt.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "matching/reported_pairs.h"

namespace linetrack {

namespace {

// Position and heading standard deviations of a covariance (heading, x, y, scale) within the
// options' observability limits.
bool Observable(const Eigen::Matrix4d& c, const VerificationOptions& options) {
  return LargestPositionSigma(c.block<2, 2>(1, 1)) <= options.max_position_sigma_m &&
         c(0, 0) <=
             DegToRad(options.max_heading_sigma_deg) * DegToRad(options.max_heading_sigma_deg);
}

// ln(e^own / (e^own + 1 + sum e^rivals)): the posterior log-probability that the line is the
// edge's image against clutter (the 1: own is a ratio against clutter) and its rivals.
double LogProbabilityTrue(const PairExplanations& explained) {
  if (!std::isfinite(explained.own)) return -std::numeric_limits<double>::infinity();
  double top = std::max(explained.own, 0.0);
  for (const double r : explained.rivals)
    top = std::max(top, r);
  double sum = std::exp(explained.own - top) + std::exp(-top);
  for (const double r : explained.rivals)
    sum += std::exp(r - top);
  return explained.own - top - std::log(sum);
}

}  // namespace

bool DeletedGroupPose(const VerificationContext& context, const VerifiedPose& verified,
                      const std::vector<size_t>& removed, const Eigen::Matrix4d& prior_information,
                      Eigen::Vector4d* shift, Eigen::Matrix4d* covariance) {
  std::vector<std::pair<int, int>> pairs;
  for (const size_t i : removed)
    pairs.push_back(verified.pairs.at(i));
  const std::vector<LineMatch> matches = ToLineMatches(context, pairs);
  const Eigen::Index n = static_cast<Eigen::Index>(2 * matches.size());
  Eigen::MatrixXd j(n, 4);
  Eigen::VectorXd r(n);
  for (size_t k = 0; k < matches.size(); ++k) {
    Eigen::Matrix<double, 2, 4> jk;
    r.segment<2>(2 * k) =
        matches[k].whitening *
        EndpointResiduals(matches[k], *context.camera, context.height, context.tilt,
                          {verified.pose, verified.refinement.focal_scale}, &jk);
    j.middleRows<2>(2 * k) = matches[k].whitening * jk;
  }
  const Eigen::Matrix4d& c = verified.refinement.covariance;
  if (!c.allFinite()) return false;
  Eigen::Matrix4d deleted;
  if (prior_information.isZero(0.0)) {
    // Woodbury: (C^-1 - J'J)^-1 = C + C J' (I - J C J')^-1 J C.
    const Eigen::MatrixXd complement = Eigen::MatrixXd::Identity(n, n) - j * c * j.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(complement, Eigen::EigenvaluesOnly);
    if (!(eig.eigenvalues().minCoeff() > 1e-6)) return false;  // the group alone fixes a direction
    deleted = c + c * j.transpose() * complement.ldlt().solve(j * c);
  } else {
    // With the prior's information on both sides: C + (A - J'J)^-1 - A^-1, A = C^-1 + P (the
    // increase that removing the group gives, bounded by the prior; C itself is not narrowed).
    const Eigen::Matrix4d with_prior =
        Eigen::LDLT<Eigen::Matrix4d>(c).solve(Eigen::Matrix4d::Identity()) + prior_information;
    const Eigen::Matrix4d information = with_prior - j.transpose() * j;
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(0.5 * (information + information.transpose()));
    const Eigen::LDLT<Eigen::Matrix4d> ldlt_all(0.5 * (with_prior + with_prior.transpose()));
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0) ||
        ldlt_all.info() != Eigen::Success || !(ldlt_all.vectorD().minCoeff() > 0.0)) {
      return false;
    }
    const Eigen::Matrix4d bounded = ldlt.solve(Eigen::Matrix4d::Identity());
    deleted = c + bounded - ldlt_all.solve(Eigen::Matrix4d::Identity());
    *shift = bounded * j.transpose() * r;  // the prior centred at the pose: no pull of its own
    *covariance = 0.5 * (deleted + deleted.transpose());
    return covariance->allFinite() && shift->allFinite();
  }
  deleted = 0.5 * (deleted + deleted.transpose());
  if (!deleted.allFinite()) return false;
  // The Gauss-Newton step of the others from the pose (their gradient is minus the group's).
  *shift = deleted * j.transpose() * r;
  *covariance = deleted;
  return true;
}

Eigen::Matrix4d PriorInformation(const PriorRegion& prior) {
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  const double radius = std::max(prior.radius, 0.01);
  const double width = std::max(prior.heading.Width(), DegToRad(0.1));
  information(0, 0) = 12.0 / (width * width);
  information(1, 1) = information(2, 2) = 4.0 / (radius * radius);
  return information;
}

Eigen::Matrix4d DoubtedCovariance(const VerificationContext& context,
                                  const VerificationOptions& options, const VerifiedPose& verified,
                                  const std::vector<std::pair<int, int>>& reported,
                                  std::vector<DoubtedGroup>* groups) {
  const Eigen::Matrix4d& c = verified.refinement.covariance;
  if (groups != nullptr) groups->clear();
  std::map<int, std::vector<size_t>> by_edge;
  for (size_t i = 0; i < verified.pairs.size(); ++i) {
    if (std::find(reported.begin(), reported.end(), verified.pairs[i]) == reported.end()) {
      by_edge[verified.pairs[i].first].push_back(i);
    }
  }
  const Eigen::Matrix4d prior_information =
      context.prior != nullptr ? PriorInformation(*context.prior) : Eigen::Matrix4d::Zero();
  Eigen::Matrix4d total = c;
  for (const auto& [edge, indices] : by_edge) {
    DoubtedGroup group;
    for (const size_t i : indices)
      group.pairs.push_back(verified.pairs[i]);
    // Without the group the pose may be unobservable: then the prior region bounds it.
    bool ok = DeletedGroupPose(context, verified, indices, Eigen::Matrix4d::Zero(), &group.shift,
                               &group.covariance) &&
              Observable(group.covariance, options);
    if (!ok && context.prior != nullptr) {
      group.bounded_by_prior = true;
      ok = DeletedGroupPose(context, verified, indices, prior_information, &group.shift,
                            &group.covariance);
    }
    if (!ok) continue;  // no prior to bound it: the pose's own covariance (first-order limit)
    Pose3Dof pose = verified.pose;
    pose.heading = WrapAngle(pose.heading + group.shift(0));
    pose.x += group.shift(1);
    pose.y += group.shift(2);
    const double scale = verified.refinement.focal_scale + group.shift(3);
    // The lines and their uncertainty from the pose without the group (a line must not confirm
    // for itself); which edges are in view, over which stretch and unhidden, from the pose where
    // the pairs were found (a small shift must not push a seen edge out of the frame).
    ExplainFrom from;
    from.seen = PoseAndScale{verified.pose, verified.refinement.focal_scale};
    from.beyond_gates = true;  // a gate is a shortcut for search, not a probability of zero
    // A rival line another edge of the interpretation explains is that pair undone, not free.
    from.interpretation = &verified.pairs;
    // Every pair of the group judged at the pose without all of it (not each at the pose of the
    // group's other pairs): two false lines on one edge must not confirm each other.
    double log_true = 0.0;
    for (const auto& pair : group.pairs) {
      log_true += LogProbabilityTrue(
          ExplainPair(context, options, {pose, scale}, group.covariance, pair, from));
    }
    group.probability_true = std::exp(log_true);
    const double doubt = 1.0 - group.probability_true;
    total += doubt * ((group.covariance - c) + group.shift * group.shift.transpose());
    if (groups != nullptr) groups->push_back(std::move(group));
  }
  return total;
}

}  // namespace linetrack

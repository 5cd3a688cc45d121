// Hypothesis verification (paper, section 3.3), with a likelihood model in place of thresholds:
// the pose of a hypothesis by Levenberg-Marquardt on whitened endpoint residuals (with the focal
// scale), the candidate edges projected with it, every observed line assigned to the edge that
// explains it best under the line noise model (or to clutter), the pose re-estimated, and the
// result scored as a log-likelihood ratio against "every line is clutter" (docs/matching.md).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "matching/constraints.h"
#include "matching/interpretation_tree.h"
#include "matching/line_fit.h"
#include "matching/pose_refinement.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"

namespace linetrack {

struct VerificationOptions {
  // Pairs are candidates below this chi-square (2 dof; 13.8 = 99.9 %) of their endpoint
  // residuals, overhanging the projected edge by at most extent_sigmas standard deviations.
  double gate_chi2 = 13.8;
  double extent_sigmas = 3.0;
  int guided_rounds = 3;  // assignment + re-estimation rounds (fewer when it stops changing)
  // A hypothesis whose own pairs have a chi-square beyond this quantile of chi2(2n - 3) at its
  // pose is inconsistent: rejected before guided matching (the early-out for hopeless ones).
  double hypothesis_quantile = 0.999;
  // An inconsistent hypothesis is restarted from the largest subset of its pairs that agrees
  // with a minimal pose of two of them: whitened residuals (chi-square, 2 dof) there below this
  // (loose: a minimal pose ignores the calibration error and the other pairs).
  double consensus_chi2 = 50.0;
  // Evidence of a pose: each visible model edge piece of at least min_detectable_px pixels is
  // detected with LineNoise::detection_probability (the missing part of it costs ln(1 - p)).
  double min_detectable_px = 30.0;
  double visibility_step_px = 12.0;  // spacing of the occlusion samples along projected edges
  // Decision: the accepted pose must be e^ambiguity_nats times likelier than any distinct pose
  // (farther than same_pose_m or same_pose_deg), explain at least min_matches model edges (the
  // paper's k), and its evidence must exceed chance_nats plus the look-elsewhere term
  // ln(prior volume / pose volume) (RequiredEvidence). A correspondence is reported when its
  // explanation is e^report_nats times likelier than any other for its line (another edge,
  // clutter, or a rival line over the same stretch of the edge).
  double ambiguity_nats = 4.6;
  double chance_nats = 4.6;
  double report_nats = 7.6;
  int min_matches = 4;
  int min_confident_edges = 1;
  double same_pose_m = 0.5;
  double same_pose_deg = 5.0;
  // The tree does not explore again regions within this many standard deviations of a
  // verified plausible pose.
  double neighbourhood_sigmas = 3.0;
  // Bound of the tree search: a line is counted for this share of its cap
  // (MaxLogLikelihoodRatio). Not a strict bound but a typical share: true poses reach about two
  // thirds of their lines' caps (docs/matching.md, section 2), so 0.7 cuts the subtrees that
  // could only win with better-than-typical lines, and the truth, searched first by iterative
  // deepening, is rarely one of them.
  double cap_efficiency = 0.7;
  // Work budget of the verification (deterministic): (line, visible edge) pairs guided matching
  // may test over all hypotheses of one localisation; then no more hypotheses are verified.
  long max_pair_tests = 800000;
  // Observability: an accepted pose's standard deviations (noise model) must be below these.
  double max_position_sigma_m = 0.5;
  double max_heading_sigma_deg = 5.0;
  // The accepted pose's covariance does not lean on an unreported pair whose leverage (largest
  // eigenvalue of J_i C J_i') reaches this: without it a variance of the pose grows by at least
  // 1 / (1 - leverage), 4 times at 0.75 (LowLeverageRefinement, pose_decision.h).
  double max_unreported_leverage = 0.75;
  // The accepted pose's covariance then also averages over what its unreported pairs are: each
  // edge's unreported pairs are false with their posterior probability, and the pose is then
  // the pose without them (law of total covariance, DoubtedCovariance in unreported_doubt.h).
  bool doubt_unreported_pairs = true;
  // A pose may leave the prior disk by prior_margin_m plus prior_margin_sigmas of its position
  // standard deviation, and the heading interval likewise.
  double prior_margin_m = 0.05;
  double prior_margin_deg = 0.5;
  double prior_margin_sigmas = 3.0;
  double wall_margin_m = 0.1;  // and must be this far from walls and obstacles
  // Levenberg-Marquardt of the hypotheses, stopping at steps below 1e-4 (0.1 mm, 0.006 degrees,
  // far below the poses' noise) instead of converging to rounding: fewer iterations per leaf.
  PoseRefinementOptions refinement = [] {
    PoseRefinementOptions o;
    o.step_tolerance = 1e-4;
    return o;
  }();

  bool Check(std::string* why) const;
};

// What a localisation problem looks like to the verifier.
struct VerificationContext {
  const std::vector<MatchEdge>* edges = nullptr;  // candidate edges
  const std::vector<ObservedLine>* lines = nullptr;
  const CameraIntrinsics* camera = nullptr;  // undistorted model, image size known
  double height = 0.0;
  double tilt = 0.0;
  // Faces of the model: a line is matched to an edge only where the edge is not hidden.
  const OcclusionTester* occlusion = nullptr;
  // A plausible pose lies within the prior (widened by the options' margins) and, when given,
  // inside the navigable area.
  const PriorRegion* prior = nullptr;
  const NavigableArea* area = nullptr;
  LineNoise noise;  // line noise and calibration error (focal_relative)
  // When set, a pair (edge index, line index) guided matching may not use (a rival without it).
  std::pair<int, int> excluded_pair = {-1, -1};
  // The camera's known roll about its optical axis (radians, RobotPose's): the lines are those
  // the unrolled camera sees (UnrolledLines, localizer.h) and poses are projected without the
  // roll; only the frustum of what the image shows is the rolled camera's.
  double roll = 0.0;
};

// The work of the verification, for the localizer's deterministic budget: the (line, visible
// edge) pairs guided matching tested.
struct VerificationStats {
  long pair_tests = 0;
};

// Evidence for a pose (nats): the log-likelihood ratio of the observed lines under "the camera is
// here" against "every line is clutter".
struct PoseEvidence {
  double lines_nats = 0.0;    // sum of the assigned lines' log-likelihood ratios
  double edges_nats = 0.0;    // detection term of the predicted visible edges (<= 0)
  double predicted_px = 0.0;  // visible length of the candidate edges (pieces counted)
  double covered_px = 0.0;    // of which assigned lines cover
  double Support() const { return predicted_px > 0.0 ? covered_px / predicted_px : 0.0; }
  double Score() const { return lines_nats + edges_nats; }
};

// A verified hypothesis.
struct VerifiedPose {
  Pose3Dof pose;
  std::vector<std::pair<int, int>> pairs;  // (edge index, line index), after guided matching
  // The pairs whose explanation is clearly the best for their line: the correspondences reported.
  std::vector<std::pair<int, int>> confident_pairs;
  int matched_edges = 0;          // distinct edges in pairs
  double mean_distance_px = 0.0;  // mean eq. 9 distance over the pairs
  double score_px = 0.0;          // eq. 10 partial Hausdorff distance (k = min_matches)
  PoseRefinementResult refinement;
  PoseEvidence evidence;  // lines term always; edges term once Complete() has run
  bool evidence_complete = false;
  bool plausible = false;           // within the prior, enough edges, observable
  std::string implausible_because;  // the first check that failed (empty when plausible)
  // Plausible but for its observability (position or heading sigma too large) or for being held
  // at the prior's border by the refinement (its pairs alone put it outside): a pose inside the
  // prior that explains the lines but cannot be answered; still a rival of the accepted pose.
  bool unobservable = false;
};

// The line-fit model of the verification (noise of the context, gates of the options).
LineFitModel FitModel(const VerificationContext& context, const VerificationOptions& options);

// Pairs as LineMatches whitened by the noise model with levers from the segment's own middle
// (the projection is not known yet).
std::vector<LineMatch> ToLineMatches(const VerificationContext& context,
                                     const std::vector<std::pair<int, int>>& pairs);

// The verification's refinement options with the prior as bounds (PoseBounds): the prior disk
// and heading interval widened by the options' margins, as the plausibility check widens them.
PoseRefinementOptions RefinementOptions(const VerificationContext& context,
                                        const VerificationOptions& options);

// The pose of a hypothesis (pairs of edge/line indices) by Levenberg-Marquardt from each of the
// `starts`, the lowest cost kept; not yet re-matched nor scored.
VerifiedPose RefineHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options);

// The most evidence (nats) a refined hypothesis' own pairs give at its pose: their
// log-likelihood ratios with no pose uncertainty (guided matching then moves the pose little and
// a maximal leaf leaves few lines to add). A cheap early-out before guided matching.
double HypothesisEvidence(const VerificationContext& context, const VerificationOptions& options,
                          const VerifiedPose& hypothesis);

// The consensus set of a verified pose: every (edge index, line index) pair whose whitened
// endpoint residuals at its pose and focal scale are within gate_chi2 (sorted). A hypothesis most
// of whose pairs are in it would be verified into that pose again.
std::vector<std::pair<int, int>> ConsensusSet(const VerificationContext& context,
                                              const VerificationOptions& options,
                                              const VerifiedPose& verified);

// Guided matching from `start` (options.guided_rounds rounds of assignment and re-estimation),
// then the plausibility checks and the lines term of the evidence. `stats`, when given, counts
// the pairs tested.
VerifiedPose Rematch(const VerificationContext& context, const VerifiedPose& start,
                     const VerificationOptions& options, VerificationStats* stats = nullptr);

// RefineHypothesis, TrimHypothesis (hypothesis_trimming.h), then Rematch (a hypothesis that cannot
// be made consistent is returned implausible without guided matching).
VerifiedPose VerifyHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options);

// Adds the detection term of the predicted visible edges (with occlusion) to the evidence.
void CompleteEvidence(const VerificationContext& context, const VerificationOptions& options,
                      VerifiedPose* verified);

// True when two refined hypotheses of the same pairs are one pose: positions within 1 cm,
// headings within 0.1 degree and focal scales within 0.1 % (a hundred times the verification's
// Levenberg-Marquardt step tolerance, far below the poses' noise of centimetres and tenths of a
// degree). Guided matching from either gives the same verified pose (the localizer verifies it
// once).
bool SameRefinedPose(const Pose3Dof& a, double scale_a, const Pose3Dof& b, double scale_b);

}  // namespace linetrack

// Hypothesis verification (paper, section 3.3): pose by Levenberg-Marquardt, model edges
// projected with it, observed lines matched to them by the segment distance (eq. 9), the
// correspondence set re-estimated, and the result scored (eq. 10) and judged reliable or not.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "matching/constraints.h"
#include "matching/interpretation_tree.h"
#include "matching/pose_refinement.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"

namespace linetrack {

struct VerificationOptions {
  double match_distance_px = 6.0;  // eq. 9 distance below which a line matches an edge
  double match_angle_deg = 4.0;    // and angle between the line and the projected edge
  int guided_rounds = 2;           // re-matching + re-estimation rounds
  double overlap_px = 5.0;         // lines of one edge overlapping more than this are rivals
  double rival_factor = 1.5;       // lines within this x match_distance_px compete for an edge

  double max_mean_distance_px = 3.5;  // mean eq. 9 distance of an acceptable pose's pairs
  double max_rms_px = 6.5;            // endpoint RMS of an acceptable pose
  int min_matches = 4;                // distinct model edges matched in an accepted pose
  int min_confident_edges = 3;        // uncontested correspondences an accepted pose must report
  // Share of the predicted visible model-edge length (edges projecting longer than
  // support_min_length_px, with occlusion) that observed lines cover.
  double min_support = 0.7;
  double support_min_length_px = 40.0;
  double support_distance_px = 10.0;  // a line within this (eq. 9) and angle confirms an edge
  double support_angle_deg = 6.0;
  double evidence_sigma_px = 3.0;  // a supporting line weighs exp(-d^2 / 2 sigma^2)
  // An explained line counts its length plus this: a short line fitting an edge exactly is
  // strong evidence too.
  double line_bonus_px = 60.0;
  double max_position_sigma_m = 0.15;  // per pixel of noise (pose observability)
  double max_heading_sigma_deg = 1.5;  // per pixel of noise
  double prior_margin_m = 0.5;         // a pose may leave the prior disk by this much
  double prior_margin_deg = 5.0;       // and the heading interval by this much
  double wall_margin_m = 0.1;          // and must be this far from walls and obstacles
  // A different pose (farther than these) whose evidence score reaches ambiguity_ratio of the
  // best one's is an ambiguity: no answer. Only the `finalists` best hypotheses (by matched
  // edges) are scored with occlusion.
  double ambiguity_distance_m = 0.6;
  double ambiguity_heading_deg = 6.0;
  double ambiguity_ratio = 0.8;
  // Leaves whose own pose lies this close to a leaf already verified are not verified again.
  double duplicate_distance_m = 0.05;
  double duplicate_heading_deg = 0.5;
  int finalists = 24;
  PoseRefinementOptions refinement;

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
  // Relative focal-length uncertainty (LineNoise::focal_relative): a calibration error moves a
  // line by up to focal_relative x its distance from the principal point, so the distance
  // thresholds grow with that distance.
  double focal_relative = 0.0;
};

// A verified hypothesis.
struct VerifiedPose {
  Pose3Dof pose;
  std::vector<std::pair<int, int>> pairs;  // (edge index, line index), after guided matching
  // The pairs no other line contests: the correspondences reported.
  std::vector<std::pair<int, int>> confident_pairs;
  int matched_edges = 0;          // distinct edges in pairs
  double mean_distance_px = 0.0;  // mean eq. 9 distance over the pairs
  double score_px = 0.0;          // eq. 10 partial Hausdorff distance (k = min_matches)
  PoseRefinementResult refinement;
  bool plausible = false;           // passed the RMS and observability checks
  std::string implausible_because;  // the first check that failed (empty when plausible)
};

// The pose of a hypothesis (pairs of edge/line indices) by Levenberg-Marquardt from each of the
// `starts`, the lowest residual kept; not yet re-matched nor scored.
VerifiedPose RefineHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options);

// RefineHypothesis, then matches all candidate edges to lines at that pose and re-estimates
// (guided rounds), and scores.
VerifiedPose VerifyHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options);

// Guided matching at a pose: `for_pose` are the pairs the pose is estimated from, `confident`
// those of them no other line contests (the correspondences reported).
struct GuidedMatching {
  std::vector<std::pair<int, int>> for_pose;
  std::vector<std::pair<int, int>> confident;
};

// Matches every line to the nearest candidate edge projected at `pose` (focal lengths scaled by
// `focal_scale`) (eq. 9 distance and
// angle under the options' thresholds), skipping edges hidden where the line lies; lines of one
// edge that overlap along it are all dropped. Returns (edge index, line index) pairs.
GuidedMatching GuidedMatches(const VerificationContext& context, const Pose3Dof& pose,
                             double focal_scale, const VerificationOptions& options);

// Re-matches and re-estimates from `start` (options.guided_rounds rounds), then scores.
VerifiedPose Rematch(const VerificationContext& context, const VerifiedPose& start,
                     const VerificationOptions& options);

// Orders verified poses: more matched edges first, then the smaller mean distance.
bool BetterThan(const VerifiedPose& a, const VerifiedPose& b);

// Evidence for a pose beyond its own correspondences: the model edges predicted visible there
// (with occlusion, all model edges) against the observed lines.
struct PoseEvidence {
  double predicted_px = 0.0;  // visible edge length predicted (edges longer than the minimum)
  double covered_px = 0.0;    // of which lies along observed lines near it
  double fitted_px = 0.0;     // the same, each line weighted by how well it fits
  double explained_px = 0.0;  // observed line length near predicted edges, weighted by the fit
  double Support() const { return predicted_px > 0.0 ? covered_px / predicted_px : 0.0; }
  // Observed length explained minus predicted length missing (pixels): the ranking score.
  double Score() const { return explained_px - (predicted_px - fitted_px); }
};

PoseEvidence Evidence(const VerificationContext& context, const WireframeModel& model,
                      const OcclusionTester& occlusion, const VerifiedPose& verified,
                      const VerificationOptions& options);

}  // namespace linetrack

// Camera localisation from image lines against a wireframe model, from a rough prior: the
// three stages of Ait Aider, Hoppenot and Colle (RAS 2005) -- correspondence-space reduction by
// view-invariant regions, interpretation-tree hypothesis generation, verification.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "matching/interpretation_tree.h"
#include "matching/observed_line.h"
#include "matching/verification.h"
#include "models/camera.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/view_invariant_regions.h"
#include "models/wireframe.h"

namespace linetrack {

// How hypotheses are generated: the paper's interpretation tree, or hypothesise-and-test by the
// options' sampler (the benchmark's baseline: random pairs of correspondences, no tree;
// matching/evaluation/baseline_sampler.h).
enum class MatchMethod { kInterpretationTree, kHypothesizeAndTest };

// Hypothesise-and-test without the tree: draws hypotheses inside the prior region, verifies each
// against the context's lines with `verification`, and returns every verified pose; *samples
// counts its draws.
using HypothesisSampler = std::function<std::vector<VerifiedPose>(
    const VerificationContext& context, const PriorRegion& prior,
    const VerificationOptions& verification, int* samples)>;

struct LocalizerOptions {
  MatchMethod method = MatchMethod::kInterpretationTree;
  LineNoise noise;  // measurement noise the margins come from
  InterpretationTreeOptions tree;
  HypothesisSampler sampler;  // required by kHypothesizeAndTest
  VerificationOptions verification;
  // Budgets (nodes, checks, leaves, guided-matching pair tests) of each search over the lines an
  // exhausted search's best pose leaves unexplained, as a share of the main search's (two such
  // searches at most: the time of a localisation stays within 1 + 2 x this of the budget's).
  double unexplained_search_share = 0.25;
  // Budgets of the search of the root branches an exhausted main search did not reach in the
  // pass it stopped in (after the searches over unexplained lines), as a share of the main
  // search's: depth first, the root's first branch can take the whole budget while its siblings
  // have the same bound.
  double unsearched_branches_share = 0.1;
  // A query that keeps more candidate edges gets more of every budget above (nodes, checks,
  // leaves, pair tests): x candidates / budget_reference_edges, between 1 and max_budget_scale.
  // A fixed budget covers less of a larger search, and answers from an exhausted search are
  // where wrong ones come from (docs/matching.md). 35 is the generated building's median query.
  double budget_reference_edges = 35.0;
  double max_budget_scale = 2.0;

  bool Check(std::string* why) const;
};

// `options` with its search budgets scaled for a query of `candidate_edges` edges
// (LocalizerOptions::budget_reference_edges, max_budget_scale).
LocalizerOptions BudgetsForCandidates(LocalizerOptions options, int candidate_edges);

// One localisation problem: undistorted image segments (pixels) and the prior.
struct LocalizationProblem {
  std::vector<Segment2> lines;
  Pose3Dof prior;          // x, y (metres), heading (radians)
  double delta_t = 0.0;    // prior position bound (metres)
  double delta_phi = 0.0;  // prior heading bound (radians)
  double height = 0.0;     // camera height: world z of the optical centre (metres)
  double tilt = 0.0;       // camera tilt (radians, positive down)
  // Known roll of the camera about its optical axis (radians, RobotPose's; a mount's): the lines
  // are matched in the image of the unrolled camera (UnrolledLines) and the pose found has it.
  double roll = 0.0;
  // When set, these model edge ids are the candidates instead of the view-invariant regions'
  // answer (e.g. a tracker that knows which edges it sees).
  std::optional<std::vector<int>> candidate_edges;
};

// A finalist of the verification, for diagnostics.
struct Finalist {
  Pose3Dof pose;
  int matched_edges = 0;
  double mean_distance_px = 0.0;
  PoseEvidence evidence;
  std::vector<std::pair<int, int>> matches;  // (model edge id, line index)
};

// Unreported pairs of one model edge that the answer's covariance doubts, for diagnostics.
struct DoubtedMatches {
  std::vector<std::pair<int, int>> matches;  // (model edge id, line index)
  double probability_true = 1.0;             // posterior that all are the edge's image
};

struct LocalizationResult {
  bool found = false;
  RobotPose pose;                                                    // valid when found
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();  // ViSP's cMo
  std::vector<std::pair<int, int>> matches;  // (model edge id, line index), sorted
  double score_px = 0.0;     // eq. 10 partial Hausdorff distance of the accepted pose
  double support = 0.0;      // share of the predicted visible edge length that is observed
  int candidate_edges = 0;   // edges kept by the view-invariant regions
  int unary_candidates = 0;  // (edge, line) pairs passing the unary constraints
  int tree_nodes = 0;
  int tree_checks = 0;  // forward-checking tests of the tree search
  int hypotheses = 0;   // hypotheses verified (pose evaluations)
  int samples = 0;      // baseline only: random pairs drawn
  bool budget_exhausted = false;
  // The main tree search's InterpretationTreeStats::completed_bound (nats): when the budget ran
  // out, the leaves it did not visit have a bound below it.
  double tree_completed_bound = 0.0;
  // The largest completed_bound of the searches over unexplained lines (0 when none ran).
  double unexplained_completed_bound = 0.0;
  std::string reason;               // why no pose was accepted (empty when found)
  std::vector<Finalist> finalists;  // the distinct plausible poses compared, best first
  // Uncertainty of the accepted pose under the line noise model (valid when found): covariance
  // of (heading rad, x m, y m), the focal scale marginalised; its largest position axis (m) and
  // heading standard deviation (rad). When the noise model holds, the truth's squared
  // Mahalanobis distance from the pose is chi2(3) distributed (docs/matching.md).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double position_sigma_m = 0.0;
  double heading_sigma_rad = 0.0;
  // The unreported pairs `covariance` averages over, grouped by edge, with their posterior
  // (DoubtedCovariance, unreported_doubt.h).
  std::vector<DoubtedMatches> doubted;
};

class Localizer {
 public:
  // `regions` may be null: then every model edge is a candidate; `area` may be null: then poses
  // are not checked against the navigable area. The model, regions and area must outlive the
  // localizer. Throws InputError when the options or camera are invalid.
  Localizer(const WireframeModel& model, const ViewInvariantRegions* regions,
            const NavigableArea* area, const CameraIntrinsics& camera,
            const LocalizerOptions& options = {});

  // Throws InputError when the problem is malformed (NaN, empty or zero-length lines, bounds).
  LocalizationResult Localize(const LocalizationProblem& problem) const;

  // The model edges possibly visible for the problem's prior (sorted ids).
  std::vector<int> CandidateEdges(const LocalizationProblem& problem) const;

  // The tree's prior region for the problem: the prior disk and heading interval at the camera
  // height, clipped to the navigable area's bounding box when there is an area.
  PriorRegion Prior(const LocalizationProblem& problem) const;

  const CameraIntrinsics& camera() const { return camera_; }
  const LocalizerOptions& options() const { return options_; }
  const WireframeModel& model() const { return model_; }
  const NavigableArea* area() const { return area_; }
  const OcclusionTester& occlusion() const { return occlusion_; }

 private:
  const WireframeModel& model_;
  const ViewInvariantRegions* regions_;
  const NavigableArea* area_;
  CameraIntrinsics camera_;
  LocalizerOptions options_;
  OcclusionTester occlusion_;
};

// Throws InputError naming the field when the problem is malformed.
void CheckProblem(const LocalizationProblem& problem);

// Undistorted segments (pixels) of a camera rolled by `roll` about its optical axis as the same
// camera without the roll would see them: each end's normalised coordinates turned by
// UnrollImagePoint (models/robot_pose.h), back to pixels with the same intrinsics.
std::vector<Segment2> UnrolledLines(const std::vector<Segment2>& lines,
                                    const CameraIntrinsics& camera, double roll);

// The view-invariant regions' question for a problem's prior: its disk and heading interval, the
// image's bearing half-width at its tilt, the camera's height (world z, which picks the storey).
VisibilityQuery VisibilityQueryOf(const LocalizationProblem& problem,
                                  const CameraIntrinsics& camera);

}  // namespace linetrack

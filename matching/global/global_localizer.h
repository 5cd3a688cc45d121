// Localisation with no prior (the kidnapped robot): the heading candidates of the vanishing
// points (matching/heading/) turn "anywhere, any heading" into a few heading searches; in each,
// the correspondences' loci vote for the camera position (position_vote.h) and the local matcher
// verifies the vote's peaks; all verified poses are compared, and a hall that repeats itself
// gives an honest "ambiguous" with the rival poses. docs/global.md.
#pragma once

#include <string>
#include <vector>

#include "matching/global/position_vote.h"
#include "matching/heading/heading_estimator.h"
#include "matching/localizer.h"

namespace linetrack {

struct GlobalOptions {
  HeadingOptions heading;
  // Peaks of the heading vote searched (best first), each with all its symmetric headings.
  int max_heading_hypotheses = 6;
  // A weaker peak is searched only when it has at least this share of the best one's support.
  double min_support_share = 0.5;
  // Heading bound of each search: heading_sigmas x the peak's standard deviation, clamped to
  // [min_heading_bound_deg, max_heading_bound_deg].
  double heading_sigmas = 3.0;
  double min_heading_bound_deg = 2.0;
  double max_heading_bound_deg = 6.0;
  // An answer must observe at least this share of its predicted visible outline
  // (PoseEvidence::Support): over the whole hall, a pose that explains part of the image by a
  // partial repetition of the building predicts edges the image does not have (docs/global.md).
  double min_support = 0.6;
  // Explanations within near_m and near_deg of the best are the same place seen with the
  // uncertainty of a few lines: within the ambiguity margin they widen the answer's covariance
  // (NearSpreadCovariance) instead of making it ambiguous.
  double near_m = 1.5;
  double near_deg = 10.0;
  // The position vote of each heading search, and the local matcher's prior around each of its
  // peaks: delta_t (metres) and delta_phi (degrees).
  PositionVoteOptions vote;
  double verify_delta_t_m = 0.75;
  double verify_delta_phi_deg = 5.0;
  // The peaks verified: the best of all searches' peaks by votes.
  int max_verified_peaks = 24;
  // The verifications' search budgets (the tree's nodes, checks and leaves, guided matching's
  // pair tests) as a share of the local mode's: a peak's prior is small, and at a wrong peak the
  // tree spends its whole budget finding nothing.
  double verify_budget_share = 0.3;

  bool Check(std::string* why) const;
};

// One image's lines and what is known of the camera: its height and tilt, nothing else.
struct GlobalProblem {
  std::vector<Segment2> lines;  // undistorted pixels
  double height = 0.0;          // metres
  double tilt = 0.0;            // radians, positive down
};

// One heading search: the heading it is centred on and its bound.
struct HeadingSearch {
  double heading = 0.0;        // radians
  double heading_bound = 0.0;  // radians
};

// One peak of a heading search's position vote and the local matcher's answer around it.
struct PeakVerification {
  int search = -1;  // index into GlobalResult::searches
  PositionPeak peak;
  LocalizationResult result;
};

// The answer. `found` and `ambiguous` exclude each other; when ambiguous, `rivals` lists the
// distinct poses that explain the image almost equally well (best first), and no pose is picked.
struct GlobalResult {
  bool found = false;
  bool ambiguous = false;
  LocalizationResult best;  // the accepted search's result (valid when found)
  std::vector<Pose3Dof> rivals;
  std::string reason;          // why no pose (empty when found)
  HeadingCandidates headings;  // the vanishing points' answer
  std::vector<HeadingSearch> searches;
  std::vector<PeakVerification> verifications;  // every search's peaks, verified
};

// Options whose heading vote assumes the matcher's line noise (its angle and offset standard
// deviations), so that both judge a segment alike.
GlobalOptions GlobalOptionsFor(const LocalizerOptions& localizer);

// The verifications' localizer options: `localizer`'s with its search budgets scaled by
// options.verify_budget_share (at least 1 each).
LocalizerOptions VerifierOptions(const LocalizerOptions& localizer, const GlobalOptions& options);

// The searches' headings and bounds for heading candidates (pure: tested directly): the
// hypotheses of `candidates` kept by `options`, each with its symmetric headings.
std::vector<HeadingSearch> PlanHeadingSearches(const HeadingCandidates& candidates,
                                               const GlobalOptions& options);

class GlobalLocalizer {
 public:
  // The localizer must have a navigable area (the search region); it and `directions` must
  // outlive this object. Throws InputError when the options are invalid or there is no area.
  GlobalLocalizer(const Localizer& localizer, const ModelDirections& directions,
                  const GlobalOptions& options = {});

  // Throws InputError when the problem is malformed (NaN, empty or zero-length lines).
  GlobalResult Localize(const GlobalProblem& problem) const;

  // The local problem verifying one peak: the prior at the peak, options' verify_delta_t_m and
  // verify_delta_phi_deg, the candidate edges of the localizer's view-invariant regions.
  LocalizationProblem PeakProblem(const GlobalProblem& problem, const PositionPeak& peak) const;

  const PositionVote& vote() const { return vote_; }

 private:
  const Localizer& localizer_;
  Localizer verifier_;  // the localizer's model, area and camera; the budgets' share
  const ModelDirections& directions_;
  GlobalOptions options_;
  PositionVote vote_;
};

}  // namespace linetrack

// Localisation with no prior (the kidnapped robot): the heading candidates of the vanishing
// points (matching/heading/) turn "anywhere, any heading" into a few searches of the
// interpretation tree over the whole navigable area, each with the heading known within a few
// degrees; their answers are compared, and a hall that repeats itself gives an honest
// "ambiguous" with the rival poses. docs/global.md.
#pragma once

#include <string>
#include <vector>

#include "matching/heading/heading_estimator.h"
#include "matching/localizer.h"

namespace linetrack {

struct GlobalOptions {
  HeadingOptions heading;
  // Peaks of the heading vote searched (best first), each with all its symmetric headings.
  int max_heading_hypotheses = 2;
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

  bool Check(std::string* why) const;
};

// One image's lines and what is known of the camera: its height and tilt, nothing else.
struct GlobalProblem {
  std::vector<Segment2> lines;  // undistorted pixels
  double height = 0.0;          // metres
  double tilt = 0.0;            // radians, positive down
};

// One search of the tree: the heading it was centred on and its answer.
struct HeadingSearch {
  double heading = 0.0;        // radians
  double heading_bound = 0.0;  // radians
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
};

// Options whose heading vote assumes the matcher's line noise (its angle and offset standard
// deviations), so that both judge a segment alike.
GlobalOptions GlobalOptionsFor(const LocalizerOptions& localizer);

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

  // The local problem of one search: the disk around the navigable area's bounding box, the
  // search's heading and bound.
  LocalizationProblem SearchProblem(const GlobalProblem& problem,
                                    const HeadingSearch& search) const;

 private:
  const Localizer& localizer_;
  const ModelDirections& directions_;
  GlobalOptions options_;
};

}  // namespace linetrack

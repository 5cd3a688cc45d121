// The report: which correspondences of a verified pose are reported, from the explanations of
// each pair's line at the pose of the other pairs (rival edges for the line, rival lines for the
// edge, clutter; docs/matching.md, section 7).
#pragma once

#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "matching/verification.h"

namespace linetrack {

// The explanations of a pair's line at a pose `at` (covariance of heading, x, y, scale; the
// context's gates): the pair's log-likelihood ratio against clutter (nats, also when negative;
// -infinity when outside the gates there), those of its rival explanations (another edge for the
// line; another line for the edge that cannot be a fragment of the same image), and whether the
// edge has such fragments there likelier than clutter. `from` may move visibility, extent and
// occlusion to another pose, give the pair's ratio beyond the gates, and price rival lines that
// other pairs of the interpretation explain.
struct PairExplanations {
  double own = -std::numeric_limits<double>::infinity();
  std::vector<double> rivals;
  bool fragments = false;
};
struct ExplainFrom {
  // When set: the pose (and focal scale) that decides the edges' visibility, extent (frustum
  // clipping) and occlusion; the image lines and their uncertainty stay at `at`.
  std::optional<PoseAndScale> seen;
  // The pair's own ratio also beyond the gates (across the line and on its extent).
  bool beyond_gates = false;
  // When given: the interpretation's pairs (edge, line). A rival line that another edge of it
  // explains would undo that pair (a line is one edge's image at most): its ratio minus that
  // pair's.
  const std::vector<std::pair<int, int>>* interpretation = nullptr;
};
PairExplanations ExplainPair(const VerificationContext& context, const VerificationOptions& options,
                             const PoseAndScale& at, const Eigen::Matrix4d& covariance,
                             const std::pair<int, int>& pair, const ExplainFrom& from = {});

// The reported correspondences of a verified pose: those of its confident_pairs that, at the
// pose of its other pairs (DeletedPose, with that pose's covariance), are within the gates and
// beat by report_nats every other edge for the line and every rival line for the edge: another
// line that fits the edge there and cannot be the same image (it overlaps the pair's line along
// the edge, or the two are not collinear fragments), e.g. a door casing's border or a box's
// bottom beside the edge. When the edge has other lines there that are fragments of the same
// image, the pair's line must also beat clutter at that pose: a further fragment beside them
// must stand without pulling the pose toward itself (docs/matching.md, section 7).
std::vector<std::pair<int, int>> PairsBeatingRivalLines(const VerificationContext& context,
                                                        const VerificationOptions& options,
                                                        const VerifiedPose& verified);

}  // namespace linetrack

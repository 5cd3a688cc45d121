// Hypothesis generation by interpretation-tree search (Grimson and Lozano-Perez 1987; Ait Aider
// et al. 2005, section 3.2). Non-vertical edges are paired with all image lines under the unary
// constraint, vertical edges with the vertical-candidate lines under the unary wedge and the
// binary inscribed-angle constraints; along each branch the correspondences must share a common
// pose (FeasibleRegion). Leaves are maximal consistent assignments of at least k edges.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "matching/feasible_region.h"

namespace linetrack {

struct InterpretationTreeOptions {
  double gate_sigmas = 3.0;           // noise margins of every constraint, in standard deviations
  double vertical_gate_sigmas = 3.5;  // margin of the "can be a vertical edge" test of lines
  double extent_slack_px = 8.0;       // tolerance of the extent constraints at segment endpoints
  double heading_bin_deg = 0.75;      // finest heading bins of the feasible region (degrees)
  int max_bins = 96;                  // bins are split finer as the headings narrow, up to this
  int min_matches = 4;                // k: leaves with fewer correspondences are discarded
  int max_vertical_matches = 0;       // vertical correspondences per hypothesis (0: no limit)
  int bound_slack = 2;        // branch and bound: leaves smaller than best - slack are pruned
  int max_nodes = 200000;     // search budget (deterministic)
  int max_hypotheses = 1000;  // leaves kept at most

  bool Check(std::string* why) const;
};

// The prior: disk of positions and interval of headings, at known height (metres).
struct PriorRegion {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius = 0.0;
  HeadingInterval heading;
  double height = 0.0;
  double focal_px = 1000.0;  // mean focal length of the camera (pixels)
};

// A leaf: (edge index, line index) pairs into the given edge and line lists, and the pose region
// the correspondences share.
struct Hypothesis {
  std::vector<std::pair<int, int>> pairs;
  FeasibleRegion region;
};

struct InterpretationTreeStats {
  int unary_candidates = 0;  // (edge, line) pairs passing the unary constraints
  int nodes = 0;             // tree nodes expanded
  int leaves = 0;            // leaves visited
  bool budget_exhausted = false;
};

// Called on every leaf in search order. Returns the smallest leaf size still worth exploring
// (branch and bound: once a hypothesis is verified with m edges, branches that cannot reach about
// m are pruned); return 0 to keep options.min_matches.
using LeafVisitor = std::function<int(const Hypothesis&)>;

// Searches the tree depth first, assignments before skips. Deterministic: the same input gives
// the same leaves in the same order.
void SearchInterpretationTree(const std::vector<MatchEdge>& edges,
                              const std::vector<ObservedLine>& lines, const PriorRegion& prior,
                              const InterpretationTreeOptions& options, const LeafVisitor& visit,
                              InterpretationTreeStats* stats);

// All leaves (no bound beyond options.min_matches).
std::vector<Hypothesis> GenerateHypotheses(const std::vector<MatchEdge>& edges,
                                           const std::vector<ObservedLine>& lines,
                                           const PriorRegion& prior,
                                           const InterpretationTreeOptions& options,
                                           InterpretationTreeStats* stats);

}  // namespace linetrack

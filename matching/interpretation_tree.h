// Hypothesis generation by interpretation-tree search (Grimson and Lozano-Perez 1987; Ait Aider
// et al. 2005, section 3.2). Non-vertical edges are paired with all image lines under the unary
// constraint, vertical edges with the vertical-candidate lines under the unary wedge and the
// binary inscribed-angle constraints; along each branch the correspondences must share a common
// pose (FeasibleRegion). The tree is searched line by line: each line takes a candidate edge or
// none (clutter), an edge may take several collinear non-overlapping lines (fragments). Leaves
// are maximal consistent assignments of at least k edges.
//
// The search is a branch and bound on the evidence a leaf could reach: every line has a cap (the
// largest log-likelihood ratio it can contribute), a node's bound is the caps of its assigned
// lines plus those of the undecided lines with a candidate still consistent (forward checking),
// and nodes below the visitor's current bound are cut. Passes with a decreasing bound (iterative
// deepening) find the leaves that explain the most lines first, so the bound is tight early.
// docs/matching.md has the details.
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
  // Lines assigned to one edge are fragments: they may not overlap (beyond extent_slack_px) and
  // must lie on one line (FragmentChiSquare with this offset noise, pixels, below 13.8).
  double fragment_offset_px = 1.0;
  // Iterative deepening: each pass lowers the bound by this many lines' worth of caps, or by
  // this fraction of it when that is more (many lines).
  double deepening_lines = 2.0;
  double deepening_fraction = 0.4;
  int max_lines = 100;       // lines entering the tree at most: those with the largest caps
  int max_nodes = 5000;      // search budget (deterministic), over all passes
  int max_hypotheses = 200;  // leaves handed to the visitor at most
  int max_checks = 100000;   // forward-checking tests at most (the work of the nodes)

  bool Check(std::string* why) const;
};

// A leaf: (edge index, line index) pairs into the given edge and line lists, and the pose region
// the correspondences share.
struct Hypothesis {
  std::vector<std::pair<int, int>> pairs;
  FeasibleRegion region;
  // Sum of the caps of the leaf's lines: the most evidence its pose could gather from the
  // tree's view (maximal: no other line fits its region).
  double bound = 0.0;
};

// A plausible verified pose and what would be verified into it again: subtrees whose region lies
// in its neighbourhood (radius_m, heading_rad) unless their bound exceeds its evidence (the
// verified pose may hold a wrong pair; a better leaf there is a better version of the same
// answer), leaves whose region holds the pose, and subtrees all of whose leaves would have most
// of their pairs in its consensus set and fewer lines than it explains.
struct VerifiedNeighbourhood {
  Pose3Dof pose;
  // Its neighbourhood: neighbourhood_sigmas standard deviations of position and heading.
  double radius_m = 0.0;
  double heading_rad = 0.0;
  int lines = 0;          // lines the verified pose explains
  double evidence = 0.0;  // its evidence (nats): a subtree in its neighbourhood must beat it
  // Its consensus set (ConsensusSet): (edge index, line index) pairs within the gate, sorted.
  std::vector<std::pair<int, int>> consensus;
};

// True when `pairs` (edge index, line index) give a line to another edge than a verified pose
// does: a pair not in the pose's consensus set (sorted) whose line is in one of its pairs. Such
// a leaf is another interpretation, not the verified pose again, even when its region holds it.
bool AssignsLineOtherwise(const std::vector<std::pair<int, int>>& pairs,
                          const std::vector<std::pair<int, int>>& consensus);

// The root's branches an exhausted search did not reach in the pass the budget stopped: the
// root's line (index into the lines), the edges it was still to take (indices into the edges; -1:
// clutter) and that pass's bound (nats). Empty when the budget stopped the search elsewhere.
struct UnsearchedBranches {
  int line = -1;
  std::vector<int> edges;
  double bound = 0.0;
};

struct InterpretationTreeStats {
  int unary_candidates = 0;  // (edge, line) pairs passing the unary constraints
  int nodes = 0;             // tree nodes expanded
  int checks = 0;            // forward-checking tests of candidates against regions
  int leaves = 0;            // leaves handed to the visitor
  int passes = 0;            // iterative-deepening passes
  bool budget_exhausted = false;
  // Bound (nats, sum of line caps) of the last iterative-deepening pass that ran to its end: every
  // leaf whose bound reaches it was visited or cut as unable to beat the visitor's bound. When no
  // pass completed (budget, or the visitor stopped the search), the first pass's top bound (all
  // lines with a candidate); 0 when nothing was searched.
  double completed_bound = 0.0;
  UnsearchedBranches unsearched;  // set when the budget stopped the root's first branch
};

// What the tree searches: the candidate edges and the image lines (leaves' pairs index into
// them), the prior region, and each line's cap (nats; null or empty: 1 per line, so that bounds
// count lines).
struct TreeProblem {
  const std::vector<MatchEdge>* edges = nullptr;
  const std::vector<ObservedLine>* lines = nullptr;
  const PriorRegion* prior = nullptr;
  const std::vector<double>* line_caps = nullptr;
};

// Called on leaves in search order, each distinct leaf once, when its bound reaches the current
// one. Returns the smallest bound still worth exploring (the best evidence found less the
// ambiguity margin); return 0 to keep the current one.
using LeafVisitor = std::function<double(const Hypothesis&)>;

// Searches the tree depth first, assignments (lines by decreasing cap) before skips.
// `neighbourhoods` (may be null; the visitor may add to it) are read at every node. Deterministic:
// the same input gives the same leaves in the same order.
void SearchInterpretationTree(const TreeProblem& problem, const InterpretationTreeOptions& options,
                              const LeafVisitor& visit, InterpretationTreeStats* stats,
                              const std::vector<VerifiedNeighbourhood>* neighbourhoods = nullptr);

// Searches the root branches an exhausted search of the same problem did not reach, at the
// bound of the pass it stopped in, each with an equal share of the options' budgets; leaves as
// SearchInterpretationTree. `stats->budget_exhausted` stays set (the pass is still not
// complete).
void SearchUnsearchedBranches(const TreeProblem& problem, const InterpretationTreeOptions& options,
                              const UnsearchedBranches& branches, const LeafVisitor& visit,
                              InterpretationTreeStats* stats,
                              const std::vector<VerifiedNeighbourhood>* neighbourhoods = nullptr);

// All leaves with at least options.min_matches correspondences (no bound).
std::vector<Hypothesis> GenerateHypotheses(const std::vector<MatchEdge>& edges,
                                           const std::vector<ObservedLine>& lines,
                                           const PriorRegion& prior,
                                           const InterpretationTreeOptions& options,
                                           InterpretationTreeStats* stats);

}  // namespace linetrack

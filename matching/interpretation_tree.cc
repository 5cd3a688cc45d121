#include "matching/interpretation_tree.h"

#include "matching/line_fit.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <set>

namespace linetrack {

bool AssignsLineOtherwise(const std::vector<std::pair<int, int>>& pairs,
                          const std::vector<std::pair<int, int>>& consensus) {
  return std::any_of(pairs.begin(), pairs.end(), [&](const std::pair<int, int>& p) {
    if (std::binary_search(consensus.begin(), consensus.end(), p)) return false;
    return std::any_of(consensus.begin(), consensus.end(),
                       [&](const std::pair<int, int>& f) { return f.second == p.second; });
  });
}
namespace {

// The tree is searched line by line (the data-driven order of Grimson's interpretation tree):
// each image line is assigned one of its candidate model edges or none (clutter). An edge may
// take several lines when they do not overlap along it (fragments). Correspondence sets are the
// same as with the edge-major order of Ait Aider et al.; this order makes the bound tight: every
// line left unexplained removes its cap from the bound at once.
class TreeSearch {
 public:
  TreeSearch(const TreeProblem& problem, const InterpretationTreeOptions& options,
             const LeafVisitor& visit, InterpretationTreeStats* stats,
             const std::vector<VerifiedNeighbourhood>* neighbourhoods)
      : edges_(*problem.edges),
        lines_(*problem.lines),
        prior_(*problem.prior),
        options_(options),
        visit_(visit),
        stats_(stats),
        neighbourhoods_(neighbourhoods) {
    gate_.sigmas = options.gate_sigmas;
    gate_.extent_slack_px = options.extent_slack_px;
    gate_.focal_px = prior_.focal_px;
    caps_ = problem.line_caps == nullptr || problem.line_caps->empty()
                ? std::vector<double>(lines_.size(), 1.0)
                : *problem.line_caps;
  }

  // Builds the candidates and the root region; false when there is nothing to search.
  bool Prepare(FeasibleRegion* root_out) {
    BuildCandidates();
    const double min_width = DegToRad(options_.heading_bin_deg);
    FeasibleRegion root =
        FeasibleRegion::FromPrior(prior_.heading, prior_.centre, prior_.radius,
                                  std::max(min_width, prior_.heading.Width() / options_.max_bins));
    if (prior_.has_bounds) {
      for (HeadingBin& bin : root.bins) {
        bin.positions.ClipHalfPlane({1.0, 0.0}, -prior_.bounds_min.x());
        bin.positions.ClipHalfPlane({-1.0, 0.0}, prior_.bounds_max.x());
        bin.positions.ClipHalfPlane({0.0, 1.0}, -prior_.bounds_min.y());
        bin.positions.ClipHalfPlane({0.0, -1.0}, prior_.bounds_max.y());
      }
      if (root.bins.front().positions.Empty()) return false;
      root.UpdateBox();
    }
    const size_t n = lines_.size();
    decided_.assign(n, kUndecided);
    edge_lines_.assign(edges_.size(), 0);
    regions_.resize(n + 2);
    alive_.assign(n + 2, std::vector<char>(candidate_edge_.size(), 1));
    *root_out = std::move(root);
    return true;
  }

  void Run() {
    FeasibleRegion root;
    if (!Prepare(&root)) return;
    const size_t n = lines_.size();
    // Iterative deepening on the bound: from what all lines with a candidate could give, down
    // by deepening_lines mean caps or deepening_fraction of the bound per pass (the larger),
    // until the visitor's own bound is reached.
    double top = 0.0;
    int with_candidates = 0;
    for (size_t j = 0; j < n; ++j) {
      if (line_offsets_[j] == line_offsets_[j + 1]) continue;
      top += caps_[j];
      ++with_candidates;
    }
    if (with_candidates == 0) return;
    stats_->completed_bound = top;
    const double step = options_.deepening_lines * top / with_candidates;
    for (double pass = top - std::max(step, options_.deepening_fraction * top);;
         pass -= std::max(step, options_.deepening_fraction * pass)) {
      pass_bound_ = std::max(pass, 0.0);
      ++stats_->passes;
      Search(0, root);
      // The visitor stops the search by an infinite bound (its own budget): not a completed pass.
      if (!stats_->budget_exhausted && std::isfinite(visitor_bound_))
        stats_->completed_bound = pass_bound_;
      if (stats_->budget_exhausted || pass_bound_ <= visitor_bound_ || pass_bound_ <= 0.0) break;
    }
  }

  // The root branches `branches` at their pass's bound, one after the other, each with an equal
  // share of the budgets.
  void Resume(const UnsearchedBranches& branches) {
    FeasibleRegion root;
    if (branches.edges.empty() || branches.line < 0 ||
        branches.line >= static_cast<int>(lines_.size()) || !Prepare(&root)) {
      return;
    }
    const int line = branches.line;
    pass_bound_ = branches.bound;
    ++stats_->passes;
    const double share = 1.0 / static_cast<double>(branches.edges.size());
    for (const int edge : branches.edges) {
      node_limit_ = stats_->nodes + std::max(1, static_cast<int>(share * options_.max_nodes));
      leaf_limit_ = stats_->leaves + std::max(1, static_cast<int>(share * options_.max_hypotheses));
      check_limit_ = stats_->checks + std::max(1, static_cast<int>(share * options_.max_checks));
      if (edge < 0) {
        decided_[line] = kClutter;
        alive_[1] = alive_[0];
        Search(1, root);
        decided_[line] = kUndecided;
      }
      for (int c = line_offsets_[line]; edge >= 0 && c < line_offsets_[line + 1]; ++c) {
        if (candidate_edge_[c] != edge || !Enter(0, root, c, line)) continue;
        Search(1, regions_[1]);
        Unassign(c, line);
      }
      if (!std::isfinite(visitor_bound_)) break;  // the visitor's own budget
    }
    stats_->budget_exhausted = true;
  }

 private:
  static constexpr int kUndecided = -1;
  static constexpr int kClutter = -2;
  static constexpr double kFragmentGateChi2 = 13.8;  // 99.9 % of chi-square with 2 dof

  // Unary constraints: each line against the non-vertical edges and, when it can be the image of
  // a vertical edge, against the vertical ones. Lines are searched by decreasing cap: leaving
  // those unexplained lowers the bound most, so wrong branches are cut soonest.
  void BuildCandidates() {
    order_.resize(lines_.size());
    std::iota(order_.begin(), order_.end(), 0);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](int a, int b) { return caps_[a] > caps_[b]; });
    // Only the max_lines lines with the largest caps enter the tree (the budget: many clutter
    // lines); guided matching still sees all of them.
    std::vector<bool> in_tree(lines_.size(), false);
    for (size_t k = 0; k < order_.size() && static_cast<int>(k) < options_.max_lines; ++k)
      in_tree[order_[k]] = true;
    line_offsets_.assign(1, 0);
    for (size_t j = 0; j < lines_.size(); ++j) {
      for (size_t e = 0; e < edges_.size() && in_tree[j]; ++e) {
        bool pass = false;
        if (edges_[e].vertical) {
          pass = lines_[j].maybe_vertical &&
                 UnaryVertical(lines_[j], edges_[e], prior_, gate_).has_value();
        } else {
          pass = !UnaryNonVertical(lines_[j], edges_[e], prior_, gate_).empty();
        }
        if (!pass) continue;
        candidate_edge_.push_back(static_cast<int>(e));
        candidate_line_.push_back(static_cast<int>(j));
        cuts_.push_back(edges_[e].vertical
                            ? std::optional<VerticalCut>(std::in_place, lines_[j], edges_[e],
                                                         options_.gate_sigmas)
                            : std::nullopt);
      }
      line_offsets_.push_back(static_cast<int>(candidate_edge_.size()));
    }
    stats_->unary_candidates = static_cast<int>(candidate_edge_.size());
  }

  // True when `line` cannot be a further fragment of `edge`'s image: it overlaps (beyond the
  // slack) a line already assigned to it, or does not lie on the same line.
  bool OverlapsAssigned(int edge, int line) const {
    if (edge_lines_[edge] == 0) return false;
    const Segment2& s = lines_[line].pixels;
    const Eigen::Vector2d axis = (s.b - s.a) / s.Length();
    const double tolerance = gate_.extent_slack_px;
    for (const auto& [e, l] : assigned_) {
      if (e != edge) continue;
      const Segment2& t = lines_[l].pixels;
      const double t0 = (t.a - s.a).dot(axis), t1 = (t.b - s.a).dot(axis);
      const double overlap =
          std::min(std::max(t0, t1), s.Length()) - std::max(std::min(t0, t1), 0.0);
      if (overlap > tolerance ||
          FragmentChiSquare(t, s, options_.fragment_offset_px) > kFragmentGateChi2) {
        return true;
      }
    }
    return false;
  }

  // Writes `in` cut by (edge, line) into `out`; false when the pose set becomes empty or a binary
  // vertical constraint with an assigned vertical correspondence fails.
  bool Extend(int c, const FeasibleRegion& in, FeasibleRegion* out) const {
    const int edge = candidate_edge_[c], line = candidate_line_[c];
    const MatchEdge& e = edges_[edge];
    const ObservedLine& l = lines_[line];
    if (!e.vertical) return AddNonVertical(l, e, prior_.height, options_.gate_sigmas, in, out);
    // The paper's binary constraint (inscribed-angle arc meets the prior disk, left-to-right
    // order) first: cheap; then the joint cut of the binned region, which subsumes it.
    for (const auto& [other_edge, other_line] : assigned_) {
      if (edges_[other_edge].vertical &&
          !BinaryVertical(lines_[other_line], l, AngleRange(other_edge, edge),
                          options_.gate_sigmas)) {
        return false;
      }
    }
    return AddVertical(*cuts_[c], in, out);
  }

  double Bound() const { return std::max(pass_bound_, visitor_bound_); }

  // Records candidate c's assignment to `line` on the branch, and undoes it.
  void Assign(int c, int line) {
    const int edge = candidate_edge_[c];
    decided_[line] = c;
    assigned_.emplace_back(edge, line);
    assigned_caps_ += caps_[line];
    distinct_edges_ += edge_lines_[edge]++ == 0 ? 1 : 0;
    for (size_t b = 0; b < consensus_fit_.size(); ++b)
      consensus_fit_[b] += consensus_flags_[b][c];
  }
  void Unassign(int c, int line) {
    const int edge = candidate_edge_[c];
    for (size_t b = 0; b < consensus_fit_.size(); ++b)
      consensus_fit_[b] -= consensus_flags_[b][c];
    distinct_edges_ -= --edge_lines_[edge] == 0 ? 1 : 0;
    assigned_caps_ -= caps_[line];
    assigned_.pop_back();
    decided_[line] = kUndecided;
  }

  // Cuts `region` by candidate c of `line` into regions_[depth + 1] (one buffer per depth,
  // reused: copying keeps its capacity), assigns c and forward checks; false (nothing changed)
  // when c cannot extend the branch.
  bool Enter(size_t depth, const FeasibleRegion& region, int c, int line) {
    const int edge = candidate_edge_[c];
    FeasibleRegion& cut = regions_[depth + 1];
    if (OverlapsAssigned(edge, line) || !Extend(c, region, &cut)) return false;
    cut.Refine(options_.max_bins, DegToRad(options_.heading_bin_deg));
    Assign(c, line);
    ForwardCheck(depth, cut, edge, line);
    return true;
  }

  // One node: `depth` lines decided. The next line is the first undecided one (in cap order)
  // with a candidate still alive; lines without one are clutter for free (their cap is no longer
  // in the bound).
  void Search(size_t depth, const FeasibleRegion& region) {
    if (stats_->nodes >= node_limit_ || stats_->leaves >= leaf_limit_ ||
        stats_->checks >= check_limit_) {
      stats_->budget_exhausted = true;
      return;
    }
    ++stats_->nodes;
    const std::vector<char>& alive = alive_[depth];
    double reachable = 0.0;
    int open_lines = 0, next = -1;
    for (int j : order_) {
      if (decided_[j] != kUndecided) continue;
      bool any = false;
      for (int c = line_offsets_[j]; c < line_offsets_[j + 1] && !any; ++c)
        any = alive[c];
      if (!any) continue;
      reachable += caps_[j];
      ++open_lines;
      if (next < 0) next = j;
    }
    if (distinct_edges_ + open_lines < options_.min_matches ||
        assigned_caps_ + reachable < Bound() ||
        InNeighbourhood(region, assigned_caps_ + reachable) || VerifiedAgain(open_lines)) {
      return;
    }
    if (next < 0) {
      VisitLeaf(alive, region);
      return;
    }
    for (int c = line_offsets_[next]; c < line_offsets_[next + 1]; ++c) {
      if (!alive[c] || !Enter(depth, region, c, next)) continue;
      Search(depth + 1, regions_[depth + 1]);
      Unassign(c, next);
      if (depth == 0 && stats_->budget_exhausted) {  // the root's other branches: not reached
        stats_->unsearched = {next, {}, pass_bound_};
        for (int d = c + 1; d < line_offsets_[next + 1]; ++d) {
          if (alive[d]) stats_->unsearched.edges.push_back(candidate_edge_[d]);
        }
        stats_->unsearched.edges.push_back(-1);
        return;
      }
    }
    decided_[next] = kClutter;
    alive_[depth + 1] = alive;
    Search(depth + 1, region);
    decided_[next] = kUndecided;
  }

  // Forward checking: the candidates of lines not assigned that stay consistent with `region`
  // after (edge, line) was assigned, written to alive_[depth + 1].
  void ForwardCheck(size_t depth, const FeasibleRegion& region, int edge, int line) {
    const std::vector<char>& in = alive_[depth];
    std::vector<char>& out = alive_[depth + 1];
    const bool vertical = edges_[edge].vertical;
    if (views_.size() != edges_.size()) {
      views_.resize(edges_.size());
      view_stamp_.assign(edges_.size(), -1);
    }
    ++forward_checks_;
    for (size_t j = 0; j < lines_.size(); ++j) {
      const bool assigned = decided_[j] >= 0;
      for (int c = line_offsets_[j]; c < line_offsets_[j + 1]; ++c) {
        out[c] = 0;
        if (assigned || !in[c]) continue;
        ++stats_->checks;
        const MatchEdge& e = edges_[candidate_edge_[c]];
        const ObservedLine& l = lines_[j];
        if (e.vertical) {
          if (vertical && !BinaryVertical(lines_[line], l, AngleRange(edge, candidate_edge_[c]),
                                          options_.gate_sigmas)) {
            continue;
          }
          const int foot = candidate_edge_[c];
          out[c] = MeetsVertical(*cuts_[c], region,
                                 [&]() -> const BoxView& {
                                   if (view_stamp_[foot] != forward_checks_) {
                                     views_[foot] = ViewBox(region, e.foot);
                                     view_stamp_[foot] = forward_checks_;
                                   }
                                   return views_[foot];
                                 })
                       ? 1
                       : 0;
        } else {
          out[c] = MeetsNonVertical(l, e, prior_.height, options_.gate_sigmas, region) ? 1 : 0;
        }
      }
    }
  }

  // True when every leaf below would have most of its pairs fitting a verified pose and fewer
  // lines than it explains (the visitor skips those: they would be verified into it again).
  // Neighbourhoods the visitor added since the last node are indexed here first.
  bool VerifiedAgain(int open_lines) {
    if (neighbourhoods_ == nullptr) return false;
    while (consensus_flags_.size() < neighbourhoods_->size()) {
      const VerifiedNeighbourhood& neighbourhood = (*neighbourhoods_)[consensus_flags_.size()];
      std::vector<char> flags(candidate_edge_.size(), 0);
      for (size_t c = 0; c < flags.size(); ++c) {
        flags[c] =
            std::binary_search(neighbourhood.consensus.begin(), neighbourhood.consensus.end(),
                               std::make_pair(candidate_edge_[c], candidate_line_[c]));
      }
      int fit = 0;
      for (const auto& [e, l] : assigned_)
        fit += flags[decided_[l]];
      consensus_flags_.push_back(std::move(flags));
      consensus_fit_.push_back(fit);
    }
    const int most = static_cast<int>(assigned_.size()) + open_lines;
    for (size_t b = 0; b < consensus_fit_.size(); ++b) {
      if (most < (*neighbourhoods_)[b].lines && 2 * consensus_fit_[b] > most) return true;
    }
    return false;
  }

  // True when the region lies in the neighbourhood of a verified pose and its leaves cannot reach
  // that pose's evidence (`bound`): they would be the same answer, no better.
  bool InNeighbourhood(const FeasibleRegion& region, double bound) const {
    if (neighbourhoods_ == nullptr) return false;
    return std::any_of(
        neighbourhoods_->begin(), neighbourhoods_->end(), [&](const VerifiedNeighbourhood& b) {
          return bound <= b.evidence && region.Within(b.pose, b.radius_m, b.heading_rad);
        });
  }

  void VisitLeaf(const std::vector<char>& alive, const FeasibleRegion& region) {
    if (!IsMaximal(alive, region)) return;
    // A leaf consistent with a verified pose would be verified into it again: its region holds
    // the pose and it assigns no line otherwise than the pose does (a line fitting the pose with
    // another edge). A leaf giving a line to another edge is another interpretation, however wide
    // its region (3-sigma gates) is: verified.
    if (neighbourhoods_ != nullptr &&
        std::any_of(
            neighbourhoods_->begin(), neighbourhoods_->end(), [&](const VerifiedNeighbourhood& b) {
              return !AssignsLineOtherwise(assigned_, b.consensus) && region.Contains(b.pose);
            })) {
      return;
    }
    Hypothesis leaf{assigned_, region, assigned_caps_};
    std::vector<std::pair<int, int>> key = leaf.pairs;
    std::sort(key.begin(), key.end());
    if (!visited_.insert(std::move(key)).second) return;
    ++stats_->leaves;
    visitor_bound_ = std::max(visitor_bound_, visit_(leaf));
  }

  // Inscribed-angle range of two vertical edges over the prior disk, computed once per pair.
  const HeadingInterval& AngleRange(int edge1, int edge2) const {
    const size_t key = static_cast<size_t>(edge1) * edges_.size() + edge2;
    if (angle_ranges_.empty()) angle_ranges_.resize(edges_.size() * edges_.size());
    if (!angle_ranges_[key]) {
      angle_ranges_[key] =
          InscribedAngleRange(edges_[edge1].foot, edges_[edge2].foot, prior_.centre, prior_.radius);
    }
    return *angle_ranges_[key];
  }

  // True when the extension keeps most of the region (at least half of its heading bins and a
  // bin of each run of contiguous bins): the leaf then adds nothing to it. An extension consistent
  // with only a part of the region (another pose cluster) does not make the leaf redundant.
  static bool KeepsEveryCluster(const FeasibleRegion& region, const FeasibleRegion& extended) {
    if (2 * extended.bins.size() < region.bins.size()) return false;
    size_t first = 0;
    for (size_t i = 1; i <= region.bins.size(); ++i) {
      const bool run_ends =
          i == region.bins.size() ||
          region.bins[i].lo - region.bins[i - 1].hi > 0.5 * (region.bins[i].hi - region.bins[i].lo);
      if (!run_ends) continue;
      const double lo = region.bins[first].lo, hi = region.bins[i - 1].hi;
      const bool kept = std::any_of(extended.bins.begin(), extended.bins.end(),
                                    [&](const HeadingBin& b) { return b.hi > lo && b.lo < hi; });
      if (!kept) return false;
      first = i;
    }
    return true;
  }

  // A leaf is kept only when no line left as clutter could have been assigned as well in every
  // pose cluster: every subset of a consistent assignment is consistent, and verifying those
  // again would be wasted work.
  bool IsMaximal(const std::vector<char>& alive, const FeasibleRegion& region) const {
    for (size_t j = 0; j < lines_.size(); ++j) {
      if (decided_[j] != kClutter) continue;
      for (int c = line_offsets_[j]; c < line_offsets_[j + 1]; ++c) {
        if (!alive[c] || OverlapsAssigned(candidate_edge_[c], static_cast<int>(j))) continue;
        if (Extend(c, region, &maximal_scratch_) && KeepsEveryCluster(region, maximal_scratch_)) {
          return false;
        }
      }
    }
    return true;
  }

  const std::vector<MatchEdge>& edges_;
  const std::vector<ObservedLine>& lines_;
  const PriorRegion& prior_;
  const InterpretationTreeOptions& options_;
  const LeafVisitor& visit_;
  InterpretationTreeStats* stats_;
  const std::vector<VerifiedNeighbourhood>* neighbourhoods_;
  Gate gate_;
  std::vector<double> caps_;
  std::vector<int> order_;  // lines by decreasing cap
  // Candidates by line: line j holds [line_offsets_[j], line_offsets_[j + 1]).
  std::vector<int> line_offsets_, candidate_edge_, candidate_line_;
  std::vector<std::optional<VerticalCut>> cuts_;  // vertical candidates' cuts
  // ForwardCheck's views of the region's box from each vertical edge's foot, valid while
  // view_stamp_[edge] == forward_checks_ (shared by the lines matched to the edge).
  std::vector<BoxView> views_;
  std::vector<long> view_stamp_;
  long forward_checks_ = 0;
  // alive_[d][c]: candidate c is still consistent with the region at depth d (forward checking).
  std::vector<std::vector<char>> alive_;
  std::vector<int> decided_;     // per line: assigned candidate, kUndecided or kClutter
  std::vector<int> edge_lines_;  // per edge: lines assigned on the current branch
  int distinct_edges_ = 0;
  std::vector<FeasibleRegion> regions_;  // per depth
  mutable FeasibleRegion maximal_scratch_;
  std::vector<std::pair<int, int>> assigned_;
  double assigned_caps_ = 0.0;
  double pass_bound_ = 0.0;
  // Budgets: the options' own, or a share of them for each unsearched branch (Resume).
  int node_limit_ = options_.max_nodes, leaf_limit_ = options_.max_hypotheses,
      check_limit_ = options_.max_checks;
  double visitor_bound_ = 0.0;
  std::set<std::vector<std::pair<int, int>>> visited_;
  // Per neighbourhood: which candidates fit its pose, and how many assigned pairs do.
  std::vector<std::vector<char>> consensus_flags_;
  std::vector<int> consensus_fit_;
  mutable std::vector<std::optional<HeadingInterval>> angle_ranges_;
};

}  // namespace

bool InterpretationTreeOptions::Check(std::string* why) const {
  if (!(gate_sigmas > 0.0) || min_matches < 2 || max_nodes < 1 || max_hypotheses < 1 ||
      !(heading_bin_deg > 0.0) || !(extent_slack_px >= 0.0) || max_bins < 1 ||
      !(deepening_lines > 0.0) || !(deepening_fraction >= 0.0 && deepening_fraction < 1.0) ||
      max_lines < 2 || max_checks < 1) {
    *why =
        "interpretation tree: gate_sigmas > 0, min_matches >= 2, budgets >= 1, "
        "deepening_lines > 0, deepening_fraction in [0, 1), max_lines >= 2";
    return false;
  }
  return true;
}

void SearchInterpretationTree(const TreeProblem& problem, const InterpretationTreeOptions& options,
                              const LeafVisitor& visit, InterpretationTreeStats* stats,
                              const std::vector<VerifiedNeighbourhood>* neighbourhoods) {
  *stats = InterpretationTreeStats();
  TreeSearch(problem, options, visit, stats, neighbourhoods).Run();
}

void SearchUnsearchedBranches(const TreeProblem& problem, const InterpretationTreeOptions& options,
                              const UnsearchedBranches& branches, const LeafVisitor& visit,
                              InterpretationTreeStats* stats,
                              const std::vector<VerifiedNeighbourhood>* neighbourhoods) {
  *stats = InterpretationTreeStats();
  TreeSearch(problem, options, visit, stats, neighbourhoods).Resume(branches);
}

std::vector<Hypothesis> GenerateHypotheses(const std::vector<MatchEdge>& edges,
                                           const std::vector<ObservedLine>& lines,
                                           const PriorRegion& prior,
                                           const InterpretationTreeOptions& options,
                                           InterpretationTreeStats* stats) {
  std::vector<Hypothesis> leaves;
  SearchInterpretationTree(
      {&edges, &lines, &prior, nullptr}, options,
      [&](const Hypothesis& h) {
        leaves.push_back(h);
        return 0.0;
      },
      stats);
  return leaves;
}

}  // namespace linetrack

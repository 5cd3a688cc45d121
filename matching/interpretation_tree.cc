#include "matching/interpretation_tree.h"

#include <algorithm>
#include <numeric>
#include <optional>

namespace linetrack {
namespace {

// One level of the tree: a model edge and the lines that pass its unary constraint, with the
// heading interval each allows.
struct Level {
  int edge = -1;
  std::vector<int> lines;
  std::vector<HeadingInterval> headings;
};

class TreeSearch {
 public:
  TreeSearch(const std::vector<MatchEdge>& edges, const std::vector<ObservedLine>& lines,
             const PriorRegion& prior, const InterpretationTreeOptions& options,
             const LeafVisitor& visit, InterpretationTreeStats* stats)
      : edges_(edges),
        lines_(lines),
        prior_(prior),
        options_(options),
        visit_(visit),
        stats_(stats),
        min_matches_(options.min_matches) {
    gate_.sigmas = options.gate_sigmas;
    gate_.extent_slack_px = options.extent_slack_px;
    gate_.focal_px = prior.focal_px;
  }

  void Run() {
    BuildLevels();
    const double min_width = DegToRad(options_.heading_bin_deg);
    const FeasibleRegion root =
        FeasibleRegion::FromPrior(prior_.heading, prior_.centre, prior_.radius,
                                  std::max(min_width, prior_.heading.Width() / options_.max_bins));
    used_.assign(lines_.size(), false);
    reachable_lines_.assign(lines_.size(), false);
    suffix_.assign(levels_.size() + 1, 0);
    regions_.resize(levels_.size() + 2);
    for (int i = static_cast<int>(levels_.size()) - 1; i >= 0; --i)
      suffix_[i] = suffix_[i + 1] + 1;
    Search(0, root);
  }

 private:
  // Unary constraints: non-vertical edges against all lines, vertical edges against the lines
  // that can be images of vertical edges. Non-vertical levels first (they narrow the heading, so
  // the vertical wedges then cut few bins), each group by candidate count, fewest first.
  void BuildLevels() {
    for (size_t e = 0; e < edges_.size(); ++e) {
      Level level;
      level.edge = static_cast<int>(e);
      for (size_t j = 0; j < lines_.size(); ++j) {
        if (edges_[e].vertical) {
          if (!lines_[j].maybe_vertical) continue;
          const std::optional<HeadingInterval> h =
              UnaryVertical(lines_[j], edges_[e], prior_.height, prior_.heading, prior_.centre,
                            prior_.radius, gate_);
          if (!h) continue;
          level.lines.push_back(static_cast<int>(j));
          level.headings.push_back(*h);
        } else {
          const std::vector<HeadingInterval> h =
              UnaryNonVertical(lines_[j], edges_[e], prior_.height, prior_.heading, prior_.centre,
                               prior_.radius, gate_);
          if (h.empty()) continue;
          level.lines.push_back(static_cast<int>(j));
          level.headings.push_back({h.front().lo, h.back().hi});
        }
      }
      stats_->unary_candidates += static_cast<int>(level.lines.size());
      if (!level.lines.empty()) levels_.push_back(std::move(level));
    }
    std::stable_sort(levels_.begin(), levels_.end(), [&](const Level& a, const Level& b) {
      if (edges_[a.edge].vertical != edges_[b.edge].vertical) return !edges_[a.edge].vertical;
      return a.lines.size() < b.lines.size();
    });
  }

  // Writes `in` cut by (edge, line) into `out`; false when the pose set becomes empty or a binary
  // vertical constraint with an assigned vertical correspondence fails.
  bool Extend(int edge, int line, const FeasibleRegion& in, FeasibleRegion* out) const {
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
    return AddVertical(l, e, options_.gate_sigmas, in, out);
  }

  void Search(size_t depth, const FeasibleRegion& region) {
    if (stats_->nodes >= options_.max_nodes || stats_->leaves >= options_.max_hypotheses) {
      stats_->budget_exhausted = true;
      return;
    }
    ++stats_->nodes;
    if (static_cast<int>(assigned_.size()) + suffix_[depth] < min_matches_ ||
        static_cast<int>(assigned_.size()) + Reachable(depth, region) < min_matches_) {
      return;
    }
    if (depth == levels_.size()) {
      if (IsMaximal(region)) {
        ++stats_->leaves;
        min_matches_ = std::max(min_matches_, visit_(Hypothesis{assigned_, region}));
      }
      return;
    }
    const Level& level = levels_[depth];
    const bool vertical = edges_[level.edge].vertical;
    const HeadingInterval headings = region.Heading();
    for (size_t c = 0; c < level.lines.size(); ++c) {
      const int line = level.lines[c];
      if (used_[line] || (vertical && VerticalsFull())) continue;
      // Cheap test first: the candidate's unary heading interval must meet the region's.
      if (level.headings[c].lo > headings.hi || level.headings[c].hi < headings.lo) continue;
      // Regions live in one buffer per depth, reused: copying keeps their capacity.
      FeasibleRegion& next = regions_[depth + 1];
      if (!Extend(level.edge, line, region, &next)) continue;
      next.Refine(options_.max_bins, DegToRad(options_.heading_bin_deg));
      used_[line] = true;
      assigned_.emplace_back(level.edge, line);
      assigned_verticals_ += vertical ? 1 : 0;
      Search(depth + 1, next);
      assigned_verticals_ -= vertical ? 1 : 0;
      assigned_.pop_back();
      used_[line] = false;
    }
    skipped_.push_back(static_cast<int>(depth));
    Search(depth + 1, region);
    skipped_.pop_back();
  }

  // The tree assigns at most options_.max_vertical_matches vertical correspondences: they are
  // weakly constrained one by one (many similar vertical lines and edges), so once a few fix the
  // pose with the non-vertical ones, the verification's guided matching finds the others.
  bool VerticalsFull() const {
    return options_.max_vertical_matches > 0 &&
           assigned_verticals_ >= options_.max_vertical_matches;
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

  // Upper bound on the levels from `depth` on that can still be matched: those with an unused
  // candidate whose unary heading interval meets the region's headings, and no more than the
  // distinct lines among those candidates (each line matches one edge).
  int Reachable(size_t depth, const FeasibleRegion& region) const {
    if (region.Empty()) return 0;
    const HeadingInterval h = region.Heading();
    int levels = 0, vertical_levels = 0;
    std::fill(reachable_lines_.begin(), reachable_lines_.end(), false);
    int lines = 0;
    for (size_t d = depth; d < levels_.size(); ++d) {
      const Level& level = levels_[d];
      const bool vertical = edges_[level.edge].vertical;
      if (vertical && VerticalsFull()) continue;
      bool any = false;
      for (size_t c = 0; c < level.lines.size(); ++c) {
        const int line = level.lines[c];
        if (used_[line] || level.headings[c].lo > h.hi || level.headings[c].hi < h.lo) continue;
        any = true;
        if (!reachable_lines_[line]) {
          reachable_lines_[line] = true;
          ++lines;
        }
      }
      if (any) (vertical ? vertical_levels : levels) += 1;
    }
    if (options_.max_vertical_matches > 0) {
      vertical_levels =
          std::min(vertical_levels, options_.max_vertical_matches - assigned_verticals_);
    }
    return std::min(levels + vertical_levels, lines);
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

  // A leaf is kept only when no skipped edge could have been matched as well in every pose
  // cluster: every subset of a consistent assignment is consistent, and verifying those again
  // would be wasted work.
  bool IsMaximal(const FeasibleRegion& region) const {
    for (int depth : skipped_) {
      const Level& level = levels_[depth];
      if (edges_[level.edge].vertical && VerticalsFull()) continue;
      for (int line : level.lines) {
        if (used_[line]) continue;
        if (Extend(level.edge, line, region, &maximal_scratch_) &&
            KeepsEveryCluster(region, maximal_scratch_)) {
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
  int min_matches_;
  Gate gate_;
  std::vector<Level> levels_;
  std::vector<int> suffix_;  // levels remaining from each depth
  std::vector<bool> used_;
  mutable std::vector<bool> reachable_lines_;  // scratch of Reachable()
  std::vector<FeasibleRegion> regions_;        // per depth
  mutable FeasibleRegion maximal_scratch_;
  std::vector<std::pair<int, int>> assigned_;
  int assigned_verticals_ = 0;
  std::vector<int> skipped_;
  mutable std::vector<std::optional<HeadingInterval>> angle_ranges_;
};

}  // namespace

bool InterpretationTreeOptions::Check(std::string* why) const {
  if (!(gate_sigmas > 0.0) || min_matches < 2 || max_nodes < 1 || max_hypotheses < 1 ||
      !(heading_bin_deg > 0.0) || !(extent_slack_px >= 0.0) || max_bins < 1) {
    *why = "interpretation tree: gate_sigmas > 0, min_matches >= 2, budgets >= 1";
    return false;
  }
  return true;
}

void SearchInterpretationTree(const std::vector<MatchEdge>& edges,
                              const std::vector<ObservedLine>& lines, const PriorRegion& prior,
                              const InterpretationTreeOptions& options, const LeafVisitor& visit,
                              InterpretationTreeStats* stats) {
  *stats = InterpretationTreeStats();
  TreeSearch(edges, lines, prior, options, visit, stats).Run();
}

std::vector<Hypothesis> GenerateHypotheses(const std::vector<MatchEdge>& edges,
                                           const std::vector<ObservedLine>& lines,
                                           const PriorRegion& prior,
                                           const InterpretationTreeOptions& options,
                                           InterpretationTreeStats* stats) {
  std::vector<Hypothesis> leaves;
  SearchInterpretationTree(
      edges, lines, prior, options,
      [&](const Hypothesis& h) {
        leaves.push_back(h);
        return 0;
      },
      stats);
  return leaves;
}

}  // namespace linetrack

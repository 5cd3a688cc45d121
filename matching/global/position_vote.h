// The camera position vote of the global mode: with the heading hypothesised (and the height and
// tilt given) the camera's rotation is known, and each (image line, model edge) correspondence
// confines the camera's plan position (x, y) to a segment, its locus. The loci of every line and
// every model edge whose direction fits the line at that heading are voted into an accumulator
// over the navigable area; its peaks are the positions the local matcher verifies.
// docs/global.md, section 1, derives the loci.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "matching/constraints.h"
#include "matching/observed_line.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"

namespace linetrack {

// A segment of camera plan positions (world x, y, metres) from `from` to `to`.
struct PositionLocus {
  Eigen::Vector2d from = Eigen::Vector2d::Zero();
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
};

// Tolerances of the loci: the extent slack at the segment's ends (pixels, for a camera of focal
// length focal_px) and the largest horizontal range from the camera to an edge (metres).
struct LocusTolerance {
  double extent_slack_px = 8.0;
  double focal_px = 1000.0;
  double max_range_m = 30.0;
};

// Vertical edge with foot F and heights [z0, z1]: the world bearing from the camera to the edge
// is h - w (w the line's bearing), so C = F - D (cos(h - w), sin(h - w)), D > 0 the horizontal
// range; each endpoint's elevation e_k puts its point at height z + D tan(e_k), which must lie
// within [z0, z1] (widened by the slack): an interval of D. Empty when no D fits.
std::optional<PositionLocus> VerticalEdgeLocus(const ObservedLine& line, const MatchEdge& edge,
                                               double height, double heading,
                                               const LocusTolerance& tolerance);

// Horizontal edge a + mu v (mu in [0, L], height p_z): endpoint k's world ray d_k = Rl(h)' r_k
// meets the plane z = p_z at C + o_k, o_k = (p_z - z) / d_kz d_k,xy (in front: (p_z - z) / d_kz
// > 0). On the edge's line: (C - a) . n = -o_k . n (n = v turned by 90 deg), the mean over both
// ends taken; within the edge: (C - a) . v in [-o_k . v, L - o_k . v] for both ends (widened by
// the slack). A segment parallel to the edge; empty when the edge is behind the camera, beyond
// the range or the interval is empty.
std::optional<PositionLocus> HorizontalEdgeLocus(const ObservedLine& line, const MatchEdge& edge,
                                                 double height, double heading,
                                                 const LocusTolerance& tolerance);

struct PositionVoteOptions {
  double cell_m = 0.3;             // accumulator cell; a locus marks its cells and their neighbours
  double heading_step_deg = 1.0;   // headings voted across a search's bound
  int peaks_per_search = 8;        // positions verified per heading search
  double peak_separation_m = 1.0;  // distinct peaks of one search are at least this far apart
  double min_line_length_px = 20.0;  // shorter lines do not vote
  double gate_sigmas = 3.0;          // direction gate of a horizontal edge
  LocusTolerance tolerance;

  bool Check(std::string* why) const;
};

// A peak of the vote: a camera position and heading, and the lines' votes there (a line votes
// once per cell its loci mark, with the weight ln(1 / share), share the part of the area's cells
// its loci mark).
struct PositionPeak {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double heading = 0.0;
  double votes = 0.0;
};

class PositionVote {
 public:
  // The accumulator covers the area's bounding box; peaks lie in the area. The area must
  // outlive this object. Throws InputError when the options are invalid.
  PositionVote(const WireframeModel& model, const NavigableArea& area,
               const PositionVoteOptions& options);

  // The best distinct peaks over headings h0 + k step within [h0 - bound, h0 + bound], best
  // first (at most peaks_per_search).
  std::vector<PositionPeak> Peaks(const std::vector<ObservedLine>& lines, double height,
                                  double heading, double bound) const;

  // The accumulator at one heading (cells row-major from the box's minimum corner, x fastest),
  // for tests and diagnosis.
  std::vector<float> Votes(const std::vector<ObservedLine>& lines, double height,
                           double heading) const;
  Eigen::Vector2d CellCentre(int index) const;
  const PositionVoteOptions& options() const { return options_; }

 private:
  struct EdgeGroup {  // horizontal edges of one direction (modulo pi)
    Eigen::Vector3d dir;
    std::vector<MatchEdge> edges;
  };
  void Vote(const std::vector<ObservedLine>& lines, const std::vector<std::vector<int>>& groups,
            double height, double heading, std::vector<float>* votes,
            std::vector<int>* stamps) const;
  // Appends the cells of the locus and their neighbours not yet stamped with `stamp`.
  void Mark(const PositionLocus& locus, int stamp, std::vector<int>* cells,
            std::vector<int>* stamps) const;
  std::vector<std::vector<int>> FittingGroups(const std::vector<ObservedLine>& lines,
                                              const HeadingInterval& headings) const;

  PositionVoteOptions options_;
  std::vector<MatchEdge> verticals_;
  std::vector<EdgeGroup> groups_;
  Eigen::Vector2d origin_;
  int nx_ = 0, ny_ = 0;
  std::vector<char> inside_;  // cell centre or a corner in the navigable area
  int inside_count_ = 0;
};

}  // namespace linetrack

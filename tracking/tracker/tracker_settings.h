// Settings of the moving-edge tracker: ViSP's moving-edge (<ecm>) and visibility (<face>)
// settings, read from a ViSP tracker XML file with ViSP's own parser, plus linetrack's choices
// (scan-line visibility, passes per frame). See docs/tracking.md.
#pragma once

#include <string>

#include "tracking/tracker/edge_refinement.h"

namespace linetrack {

// ViSP's vpMe: one moving edge is searched along the normal of a projected model edge.
struct MovingEdgeSettings {
  int mask_size = 5;          // convolution mask side (pixels, odd)
  int mask_count = 180;       // number of mask orientations over 180 degrees
  int range = 8;              // search distance on each side of the edge (pixels)
  double threshold = 5000.0;  // ViSP 3.5 raw likelihood threshold (sum of the mask response)
  double mu1 = 0.5;           // accepted contrast change, lower bound: c > (1 - mu1) c_ref
  double mu2 = 0.5;           // accepted contrast change, upper bound: c < (1 + mu2) c_ref
  double sample_step = 4.0;   // distance between moving edges along an edge (pixels)

  bool Check(std::string* why) const;
};

// Which faces and edges are considered visible (ViSP's <face> section).
struct VisibilitySettings {
  double angle_appear_deg = 85.0;     // a face becomes visible below this view angle
  double angle_disappear_deg = 89.0;  // and invisible above this one
  double near_clipping_m = 0.1;       // metres in front of the camera
  double far_clipping_m = 100.0;
  bool fov_clipping = true;  // clip faces by the field of view
  // Hidden-edge removal by scan-line rendering of the faces (occluded edge parts are not
  // tracked); needed for models whose faces hide each other (rooms, pillars).
  bool scanline = false;

  bool Check(std::string* why) const;
};

struct TrackerSettings {
  MovingEdgeSettings me;
  VisibilitySettings visibility;
  // Tracking passes per frame: each pass searches the moving edges again from the pose found by
  // the previous one, sampling them every pass_step_factor * sample_step pixels. Several passes
  // at lower density hold the pose where one pass at full density (ViSP's own track()) loses it,
  // for a little more time (docs/tracking.md, moving edges).
  int passes = 2;
  double pass_step_factor = 2.0;
  // Sub-pixel refinement of each tracked pose on the image edges (edge_refinement.h).
  bool refine_subpixel = true;
  EdgeRefinementOptions refinement;
  // Alignment of a pose predicted from the robot's odometry before tracking (StartFromPrediction).
  EdgeAlignmentOptions alignment;
  int max_iterations = 30;  // virtual visual servoing iterations per pass
  // Iterations of every pass but the last (0: max_iterations). The first pass only has to move
  // the moving edges, so capping it saves time, but the pose it hands over is rougher and more
  // frames end wrong: off by default (docs/tracking.md, speed).
  int first_passes_max_iterations = 0;
  double good_edge_ratio = 0.4;     // ViSP gives up below this share of good moving edges
  std::string source = "defaults";  // the file the settings come from, for reports

  bool Check(std::string* why) const;
};

// Settings from a ViSP tracker XML file (<conf><ecm>..</ecm><face>..</face></conf>), parsed by
// ViSP's vpMbtXmlGenericParser so that values mean exactly what they mean to ViSP (fields
// missing from the file take ViSP's parser defaults; clipping distances only when given).
// `scanline` and `passes` are not part of ViSP's format and keep the values of `base`.
// Throws InputError naming the file when it is missing, malformed or holds invalid values.
TrackerSettings ReadTrackerSettings(const std::string& path, const TrackerSettings& base = {});

}  // namespace linetrack

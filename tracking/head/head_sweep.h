// Drives a pan-tilt head through a list of angles and keeps one frame at each, taken once the
// head stands still there: the views of calibrations that need known head angles (`linetrack
// calibrate-mount` live). The camera paces the sweep: every step grabs a frame (one frame period
// of the camera's clock, the simulator's or the device's) and reads the head, so nothing sleeps.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "tracking/capture/frame_source.h"
#include "tracking/head/pan_tilt_head.h"

namespace linetrack {

struct HeadSweepOptions {
  // Still: the head reports it is not moving, within arrive_rad of the angles it was sent to, and
  // `still_readings` consecutive readings (one per frame) agree within still_rad on both axes.
  double still_rad = 1e-4;
  double arrive_rad = 0.005;
  int still_readings = 3;
  // Frames dropped once still, before the one kept (frames the camera may have buffered while
  // the head was moving).
  int discard_frames = 2;
  int max_frames_per_view = 900;  // frames waited for one view before the sweep gives up

  bool Check(std::string* why) const;
};

// One view of the sweep: the frame and the head's reading right after it was grabbed.
struct SweepView {
  Frame frame;
  HeadState head;
};

struct SweepResult {
  bool ok = false;
  std::string failure;  // why not ok (a refused move, a lost camera, a head that never settled)
  std::vector<SweepView> views;  // in the order of the angles, complete when ok
};

// Angles (pan, tilt radians) of a serpentine grid of at least `count` views centred on `centre`,
// spanning +-half_range: nc columns and nr rows with nc / nr close to the ranges' ratio, both at
// least 2, nc nr >= count; rows alternate direction so that the head travels little.
std::vector<Eigen::Vector2d> SweepGrid(const Eigen::Vector2d& centre,
                                       const Eigen::Vector2d& half_range, int count);

// Moves the head to each of `angles` in turn (MoveTo), waits until it is still, and keeps the
// next frame with the head's reading. Refused moves, failed reads or grabs (other than
// timeouts), and views that do not settle end the sweep with ok = false.
SweepResult SweepHead(PanTiltHead* head, FrameSource* source,
                      const std::vector<Eigen::Vector2d>& angles, const HeadSweepOptions& options);

}  // namespace linetrack

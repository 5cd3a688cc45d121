// The kidnapped robot of a rendered drive: at a frame the robot is lifted and put down elsewhere,
// then drives on from there as it would have. Its wheels do not turn while it is carried, so the
// odometry (simulated from the drive without the carries) sees none of it; only the truth jumps.
#pragma once

#include <string>
#include <vector>

#include "models/navigable_area.h"
#include "models/render/sequence.h"
#include "models/robot_pose.h"

namespace linetrack {

// The robot is put down at `put_down` (the base's x, y in metres and heading in radians) on
// frame `frame`.
struct Kidnap {
  int frame = 0;
  Pose3Dof put_down;
};

// The planar rigid motion W that takes the base pose `from` to `to`:
// W(p) = R(to.heading - from.heading) (p - from.xy) + to.xy, headings shifted by the same angle.
Eigen::Isometry3d PlanarCarry(const Pose3Dof& from, const Pose3Dof& to);

// "FRAME:x,y,heading_deg" (the command line's form); throws InputError naming the text.
Kidnap ParseKidnap(const std::string& text);

// The frames with each kidnap applied in turn: every frame from a kidnap's frame on is moved by
// the carry that takes the base at that frame to the put-down pose (camera poses
// cam_from_world W^-1, base and camera positions and headings by W; pan, height and tilt kept).
// Throws InputError when a kidnap's frame is not in [1, frames) or not after the previous one,
// or (with `area`) when a moved base leaves the navigable area.
std::vector<SequenceFrame> ApplyKidnaps(std::vector<SequenceFrame> frames,
                                        const std::vector<Kidnap>& kidnaps,
                                        const NavigableArea* area);

}  // namespace linetrack

// Overlay snapshots of `linetrack live` (headless: drawn into the image, no display needed): the
// model edges projected with the frame's pose, the target and the pixel it is servoed to, and a
// status line.
#pragma once

#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>
#include <Eigen/Core>
#include <vector>

#include "models/camera.h"
#include "models/occlusion.h"
#include "tracking/live/live_loop.h"

namespace linetrack {

// A colour copy of `frame` with the visible model edges `edges` (undistorted pixels, drawn
// through `camera`'s distortion so that they lie on the distorted frame) in green, the desired
// pixel as a blue cross, the target's projection as a red circle, and one status line
// (time, status, head angles, error).
vpImage<vpRGBa> DrawLiveOverlay(const vpImage<unsigned char>& frame, const LiveIteration& it,
                                const std::vector<ProjectedEdge>& edges,
                                const CameraIntrinsics& camera, const Eigen::Vector2d& desired_px);

}  // namespace linetrack

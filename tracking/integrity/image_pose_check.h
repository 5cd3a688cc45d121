// The integrity of a pose found on a single image (`localize --image`): the moving edges are
// started at the pose and track the image once, and the integrity monitor evaluates the sub-pixel
// refinement's edges and points (docs/integrity.md): the same rule as for a tracked pose.
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <optional>

#include "tracking/integrity/integrity_monitor.h"
#include "tracking/tracker/edge_tracker.h"

namespace linetrack {

// `undistorted` is the image undistorted for tracker->camera(); `known` a robot's height and tilt.
// Lost (with the reason) when the tracker cannot start or track there, or the refinement finds
// no edge points.
PoseIntegrity CheckPoseOnImage(EdgeTracker* tracker, const vpImage<unsigned char>& undistorted,
                               const Eigen::Isometry3d& cam_from_world,
                               const std::optional<KnownHeightTilt>& known,
                               const IntegrityOptions& options);

}  // namespace linetrack

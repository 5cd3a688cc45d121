#include "tracking/integrity/image_pose_check.h"

namespace linetrack {

PoseIntegrity CheckPoseOnImage(EdgeTracker* tracker, const vpImage<unsigned char>& undistorted,
                               const Eigen::Isometry3d& cam_from_world,
                               const std::optional<KnownHeightTilt>& known,
                               const IntegrityOptions& options) {
  PoseIntegrity lost;
  const EdgeTrackResult started = tracker->Start(undistorted, cam_from_world);
  if (!started.ok) {
    lost.reason = "the moving edges cannot start at the pose: " + started.reason;
    return lost;
  }
  const EdgeTrackResult tracked = tracker->Track(undistorted, false, known);
  if (!tracked.ok) {
    lost.reason = "the moving edges cannot track the image at the pose: " + tracked.reason;
    return lost;
  }
  if (tracked.observations.empty()) {
    lost.reason = "the image edges do not confirm the pose (sub-pixel refinement: " +
                  std::to_string(tracked.health.refined_points) + " points)";
    return lost;
  }
  return EvaluatePoseIntegrity(tracked.observations, tracker->camera(), tracked.cam_from_world,
                               PoseParameterisation(known), options);
}

}  // namespace linetrack

// The seam between the live loop and whatever says where the camera is: "estimate the camera
// pose of this frame, knowing the head angles and the robot's prior: a pose, or none". The
// moving-edge tracker of tracking/tracker/ (seeded by the matcher) plugs in here; the simulator's
// ground truth does too, for developing and testing the servo on its own.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "models/robot_pose.h"
#include "tracking/capture/frame_source.h"
#include "tracking/head/pan_tilt_head.h"
#include "tracking/integrity/integrity_monitor.h"

namespace linetrack {

// The state of a frame, as frames.csv reports it (the tracker's vocabulary).
enum class PoseStatus {
  kInitialising,  // no pose found yet
  kTracking,      // a pose, followed from the previous frame (or the first one)
  kLost,          // no pose on this frame after having had one
  kRelocalised,   // a pose found again after a loss
  kCoasting,      // no image pose: the last pose carried by the odometry
};

// "initialising", "tracking", "lost", "relocalised", "coasting".
const char* ToString(PoseStatus status);

// What an estimator says about one frame.
struct PoseEstimate {
  PoseStatus status = PoseStatus::kInitialising;
  std::optional<Eigen::Isometry3d> cam_from_world;  // only for kTracking and kRelocalised
  std::string source;  // where the pose came from ("tracker", "matcher", "simulator truth", ...)
  std::string note;    // why there is no pose (empty otherwise)
  double projection_error_deg = -1.0;  // the tracker's health when measured, else -1
  // The pose's integrity: tracking (within the alert limits), degraded or lost, its covariance
  // and protection levels.
  PoseUncertainty uncertainty;

  bool has_pose() const { return cam_from_world.has_value(); }
};

// Gives the camera pose of each live frame. `head` holds the angles read for the frame;
// `camera_prior` is the robot's prior for the camera (position and height from odometry and the
// head's geometry, heading = base heading + pan, tilt = head tilt: the matcher's prior).
class CameraPoseEstimator {
 public:
  virtual ~CameraPoseEstimator() = default;
  virtual PoseEstimate Estimate(const Frame& frame, const HeadState& head,
                                const RobotPose& camera_prior) = 0;
  // One line for logs and summary.json.
  virtual std::string Describe() const = 0;
};

}  // namespace linetrack

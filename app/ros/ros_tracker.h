// The one seam between the ROS node and linetrack's tracking: a frame with its stamp, the base's
// odometry moved into the map and the camera's mount go in; the status, the base's pose in the map
// and its covariance in ROS's convention come out. Built the way `replay` and `live` build their
// tracker (matcher, relocaliser, moving edges, SequenceTracker with its integrity monitor); the
// covariance is the integrity monitor's. No ROS types: the node converts messages on its side.
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>

#include "app/localize_io.h"
#include "app/ros/ros_geometry.h"
#include "matching/lines/line_extractor.h"
#include "models/camera.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/global_recovery.h"
#include "tracking/tracker/relocalizer.h"
#include "tracking/tracker/sequence_tracker.h"
#include "tracking/tracker/tracker_settings.h"

namespace linetrack::app {

struct RosTrackerOptions {
  std::string model_path;       // ViSP .cao (its frame is the map frame)
  CameraIntrinsics camera;      // of the incoming frames, with their size and distortion
  TrackerSettings settings;     // moving edges, visibility, passes
  LineExtractionOptions lines;  // line extraction of the relocaliser
  RelocalizationOptions relocalization;
  // With the integrity monitor's alert limits and noise (sequence.integrity): a pose whose
  // protection levels exceed them is degraded.
  SequenceTrackerOptions sequence;

  bool Check(std::string* why) const;
};

// The node's status vocabulary (~status): the integrity monitor's tracking and degraded for a
// pose, lost for none since a loss; relocalising while the matcher searches (no pose yet, or since
// an initial pose) and while its pose is being confirmed (ReacquisitionCheck).
enum class RosStatus { kTracking, kDegraded, kLost, kRelocalising };
const char* ToString(RosStatus status);

// The status of a frame with a pose: the integrity monitor's, relocalising for a degraded pose
// while the matcher's pose is being confirmed.
RosStatus StatusOf(IntegrityStatus integrity, bool reacquiring);

// What the node knows at an image's stamp.
struct TrackerInput {
  double t = 0.0;                     // the image's stamp (seconds)
  std::optional<Pose3Dof> odom_base;  // the base's odometry at t, in the tracker's odometry frame
  CameraMount mount;                  // head angles and height at t
};

// What the tracker says about one frame.
struct TrackedFrame {
  RosStatus status = RosStatus::kRelocalising;
  TrackStatus track_status = TrackStatus::kInitialising;
  std::string source;  // "tracker", "matcher", "restart", "start pose", "global"
  std::string note;    // why there is no pose, or why it is degraded
  std::optional<Eigen::Isometry3d> cam_from_map;
  std::optional<Eigen::Isometry3d> map_from_base;
  std::optional<Matrix6d> covariance;  // ROS convention (RosCovarianceOf), with the pose
  double track_ms = 0.0;               // the tracking step (undistortion to judged pose)
  FrameReport report;                  // the engine's own report (overlay, health)
};

class RosTracker {
 public:
  // Loads the model (and its navigable area for the matcher) and builds the tracker. Throws
  // InputError for a bad model or options.
  explicit RosTracker(const RosTrackerOptions& options);
  ~RosTracker();

  // Starts over from a prior of the base (x, y, yaw in the map) with these matcher bounds: the
  // odometry given to Process() from now on is expressed in the frame where `map_base` holds
  // at the odometry reading `odom_base` (both at the same instant); without one, at the first
  // reading Process() is given.
  void Restart(const Pose3Dof& map_base, const std::optional<Pose3Dof>& odom_base,
               const SearchBounds& bounds);

  // Drops the pose and the prior: the next frames are localised by the global mode (any position
  // in the navigable area, any heading), each answer confirmed before it is `tracking`. False
  // (nothing changed) when the model gives no global mode (no horizontal edges).
  bool RequestGlobal();
  bool has_global_mode() const { return global_ != nullptr; }

  // Tracks one grey image (distorted, of the options' camera).
  TrackedFrame Process(const vpImage<unsigned char>& image, const TrackerInput& input);

  // The last frame, undistorted (for the overlay).
  const vpImage<unsigned char>& undistorted() const { return sequence_->undistorted(); }
  const WireframeModel& model() const { return *loaded_.model; }
  const CameraIntrinsics& undistorted_camera() const { return undistorted_camera_; }
  int losses() const { return sequence_->losses(); }
  int recoveries() const { return sequence_->recoveries(); }

 private:
  RosTrackerOptions options_;
  LocalizerCache cache_;
  const LoadedModel& loaded_;
  CameraIntrinsics undistorted_camera_;
  std::unique_ptr<Localizer> localizer_;
  std::unique_ptr<Relocalizer> relocalizer_;
  std::unique_ptr<GlobalLocalizer> global_localizer_;
  std::unique_ptr<GlobalRecovery> global_;
  std::unique_ptr<EdgeTracker> tracker_;
  std::unique_ptr<SequenceTracker> sequence_;
  // The odometry frame's pose in the map at the last Restart(): odometry readings are moved into
  // the map with it before they reach the tracker.
  Eigen::Isometry3d map_from_odom_ = Eigen::Isometry3d::Identity();
  std::optional<Pose3Dof> unanchored_start_;  // a Restart() without odometry, until a reading
  bool had_pose_ = false;
};

}  // namespace linetrack::app

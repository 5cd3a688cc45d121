// `linetrack ros`: the ROS 1 node, with the conventions of ROS's laser localiser AMCL. Subscribes
// (relative names, remappable) image (image_transport), camera_info (without --camera), odom,
// the head's angles from joint_states (pan and tilt joints) or TF base -> camera, and initialpose;
// publishes ~pose (PoseWithCovarianceStamped of the base in the map, stamped with the image's
// stamp; tracking poses only) and map -> odom on /tf from them (never map -> base), ~pose_degraded
// (the other poses, with their covariance), ~status, diagnostics and ~overlay; serves
// ~global_localization. Images arriving while one is tracked replace the waiting one (the oldest is
// dropped and counted): it never lags the stream.
#pragma once

#include <ros/ros.h>

#include <atomic>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "app/global_mode_flags.h"
#include "app/integrity_output.h"
#include "app/ros/camera_mount_source.h"
#include "app/ros/ros_geometry.h"

namespace linetrack::app {

// Everything the node is told, from the command line or the parameter server (the command line
// wins). Empty strings and NaNs are "not given".
struct RosNodeOptions {
  std::string model;     // ViSP .cao; its frame is the map frame
  std::string camera;    // ViSP camera XML; empty: from camera_info
  std::string settings;  // ViSP tracker XML
  std::string map_frame = "map", odom_frame = "odom", base_frame = "base_link";
  std::string camera_frame;  // empty: the image header's frame_id
  // The head's angles: auto, joint_states, tf or fixed (HeadSource).
  std::string head = "auto";
  double height = std::numeric_limits<double>::quiet_NaN();    // camera above the base (m)
  double tilt_deg = std::numeric_limits<double>::quiet_NaN();  // without a tilt joint or TF
  std::string pan_joint, tilt_joint;  // joint_states names; empty: no such joint
  std::string mount;  // mount.json of the camera on the head (with joint_states); empty: none
  // ~alert_limit "METRES,DEGREES", ~camera_sigma, ~model_sigma: the integrity monitor's
  IntegrityFlags integrity;
  // ~kidnap_after_s, ~global_after_s, ~global_after_m: when a lost robot switches to the global
  // mode (seconds, metres; GlobalRecoveryOptions)
  GlobalModeFlags global;
  double transform_tolerance = 0.1;  // s added to map -> odom's stamp, as AMCL does
  double odom_max_gap = 0.5;         // s: odometry this far from an image's stamp is not used
  // s: how long an image waits for the odometry to reach its stamp (odometry and images come on
  // separate connections; a reading from before the image would lag the pose by its motion).
  double odom_wait = 0.05;
  double initial_bounds_scale = 1.5;  // matcher bounds = this many standard deviations

  // Throws InputError naming the parameter when a value is out of range.
  void Check() const;
  // The head's part of these options.
  CameraMountSourceOptions MountOptions() const;
};

// Fills the options not given on the command line from the private parameters (~model,
// ~camera, ~settings, ~map_frame, ~odom_frame, ~base_frame, ~camera_frame, ~head, ~height,
// ~tilt, ~pan_joint,
// ~tilt_joint, ~mount, ~alert_limit "METRES,DEGREES", ~camera_sigma, ~model_sigma,
// ~kidnap_after_s, ~global_after_s, ~global_after_m, ~transform_tolerance, ~odom_max_gap,
// ~odom_wait). `given` names the command-line flags given (without dashes, e.g. "model").
void ReadRosParameters(const ros::NodeHandle& private_nh, const std::vector<std::string>& given,
                       RosNodeOptions* options);

// Per-frame timing of the node, for `bench ros` and the closing line.
struct RosNodeStats {
  long received = 0;  // images that reached the callback
  long dropped = 0;   // replaced while waiting (the oldest first)
  long processed = 0;
  long with_pose = 0;  // on ~pose (tracking)
  long degraded = 0;   // on ~pose_degraded
  long no_mount = 0;   // not tracked: the camera's mount unknown at the stamp (TF)
  // The last frames' (at most 100000): the tracking step; the time from the worker taking the
  // image to its pose published, minus the tracking step (conversion, odometry, publishing); the
  // time the image waited for the worker after its arrival (the frame before it being tracked).
  std::vector<double> track_ms;
  std::vector<double> overhead_ms;
  std::vector<double> wait_ms;
};

class RosNode {
 public:
  // Subscribes and advertises on `nh` (topics) and `private_nh` (~pose, ~status, ...). Loads the
  // model and builds the tracker at once when the camera is known, else at the first
  // camera_info. Throws InputError for bad options or files.
  RosNode(const RosNodeOptions& options, ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~RosNode();

  // Tracks images until Stop() or ros::isShuttingDown(); call from one thread while a spinner
  // runs the callbacks.
  void Run();
  void Stop();

  RosNodeStats Stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack::app

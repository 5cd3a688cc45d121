// Where the camera is on the base at an image's stamp, for `linetrack ros`: from the pan-tilt
// head's joint_states (pan and tilt joints named by parameters, the height given, or the camera's
// calibrated mount on the head from mount.json), from TF
// base -> camera (the camera's frame from the image header, looked up at the image's stamp), or
// fixed (the height and tilt given, the camera above the base's origin looking forward).
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/head_mount.h"
#include "app/ros/ros_geometry.h"

namespace linetrack::app {

// Where the head's angles come from (~head): `auto` takes joint_states when a pan or tilt joint
// is named, else TF base -> camera when TF links the two frames, else the fixed height and tilt.
enum class HeadSource { kAuto, kJointStates, kTf, kFixed };

// Parses "auto", "joint_states", "tf" or "fixed"; throws InputError naming ~head otherwise.
HeadSource ParseHeadSource(const std::string& name);

struct CameraMountSourceOptions {
  HeadSource head = HeadSource::kAuto;
  double height = std::numeric_limits<double>::quiet_NaN();  // m; NaN: not given
  double tilt = std::numeric_limits<double>::quiet_NaN();    // radians; NaN: not given
  std::string pan_joint, tilt_joint;  // joint_states names; empty: no such joint
  // mount.json (calibration/mount_file.h) for joint_states: the camera on the head's tilt frame,
  // the axes' crossing at the base's origin, at the file's floor height or `height` taped with the
  // head level. Empty: the camera's centre at the base's origin, no head offsets.
  std::string mount;
  std::string base_frame = "base_link";
  std::string camera_frame;  // empty: the image header's frame_id
  double wait = 0.05;        // s an image waits for TF to reach its stamp
  double max_gap = 0.5;      // s: the latest TF this far from the stamp is still used
  double max_roll = 0.0873;  // radians (5 degrees): a mount rolled more is refused

  // The source in use once `auto` is resolved for the joints: kJointStates, kTf or kAuto (TF
  // when TF links the frames, else fixed).
  HeadSource Resolved() const;
  // Throws InputError naming the parameter when the chosen source lacks a value, or when a mount
  // file is given for a source other than joint_states.
  void Check() const;
};

class CameraMountSource {
 public:
  // Listens to TF on `nh` when the source may use it; reads the mount file (InputError naming it
  // when it is bad, or when it has no floor height and no height is given).
  CameraMountSource(const CameraMountSourceOptions& options, const ros::NodeHandle& nh);
  ~CameraMountSource();

  // joint_states: keeps the last seconds of the named joints' pan and tilt (any thread).
  void OnJoints(const sensor_msgs::JointState& msg);

  // The mount at the image's stamp, waiting up to `wait` for the joint states or TF to reach it;
  // nullopt with `why` when there is none (no joint state or TF near the stamp, a mount that is
  // not a level optical frame).
  std::optional<CameraMount> At(const std_msgs::Header& image, std::string* why);

  // "joint_states", "tf" or "fixed": what gave the last mount.
  std::string LastSource() const;

 private:
  std::optional<CameraMount> FromTf(const std::string& camera_frame, const ros::Time& stamp,
                                    std::string* why);
  std::optional<CameraMount> FromJoints(double t, std::string* why);
  CameraMount Fixed() const;

  CameraMountSourceOptions options_;
  std::unique_ptr<tf2_ros::Buffer> buffer_;
  std::unique_ptr<tf2_ros::TransformListener> listener_;
  mutable std::mutex mutex_;  // the joint angles and the last source
  std::condition_variable joints_arrived_;
  std::vector<StampedHeadAngles> joints_;  // sorted by time
  std::optional<BelievedHead> head_;       // with a mount file
  std::string last_source_;
};

}  // namespace linetrack::app

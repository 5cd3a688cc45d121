#include "app/ros/camera_mount_source.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "app/cli_common.h"
#include "app/ros/ros_messages.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack::app {

namespace {
constexpr double kJointHistoryS = 10.0;  // seconds of joint states kept
}  // namespace

HeadSource ParseHeadSource(const std::string& name) {
  if (name == "auto") return HeadSource::kAuto;
  if (name == "joint_states") return HeadSource::kJointStates;
  if (name == "tf") return HeadSource::kTf;
  if (name == "fixed") return HeadSource::kFixed;
  throw InputError("ros: --head (~head) is '" + name + "': give auto, joint_states, tf or fixed");
}

HeadSource CameraMountSourceOptions::Resolved() const {
  const bool joints = !pan_joint.empty() || !tilt_joint.empty();
  return head == HeadSource::kAuto && joints ? HeadSource::kJointStates : head;
}

void CameraMountSourceOptions::Check() const {
  const bool has_height = std::isfinite(height), has_tilt = std::isfinite(tilt);
  if (has_height) CheckRange(height, 0.0, 100.0, "--height");
  if (has_tilt) CheckRange(RadToDeg(tilt), -89.0, 89.0, "--tilt");
  const char* no_height = "ros: no camera height: give --height or the parameter ~height";
  const bool has_mount = !mount.empty();
  if (has_mount && Resolved() != HeadSource::kJointStates) {
    throw InputError(
        "ros: --mount (~mount) applies to the head's joint_states: give --pan-joint or "
        "--tilt-joint, not --head tf or fixed");
  }
  switch (Resolved()) {
    case HeadSource::kJointStates:
      if (pan_joint.empty() && tilt_joint.empty()) {
        throw InputError("ros: --head joint_states needs --pan-joint or --tilt-joint");
      }
      // With a mount file, its floor height or --height (BelieveHead says which is missing).
      if (!has_height && !has_mount) throw InputError(no_height);
      if (tilt_joint.empty() && !has_tilt) {
        throw InputError("ros: no tilt: give --tilt (or ~tilt), or a tilt joint (~tilt_joint)");
      }
      break;
    case HeadSource::kFixed:
      if (!has_height) throw InputError(no_height);
      if (!has_tilt) throw InputError("ros: no tilt: give --tilt or the parameter ~tilt");
      break;
    case HeadSource::kAuto:
      if (has_height != has_tilt) {
        throw InputError(
            "ros: give both --height and --tilt (a camera fixed on the base) or neither (the "
            "mount from TF base -> camera)");
      }
      break;
    case HeadSource::kTf:
      break;
  }
  CheckRange(wait, 0.0, 1.0, "--odom-wait");
  CheckRange(max_gap, 0.0, 10.0, "--odom-max-gap");
  if (base_frame.empty()) throw InputError("ros: frame names must not be empty");
}

CameraMountSource::CameraMountSource(const CameraMountSourceOptions& options,
                                     const ros::NodeHandle& nh)
    : options_(options) {
  options_.Check();
  const HeadSource source = options_.Resolved();
  if (source == HeadSource::kTf || source == HeadSource::kAuto) {
    buffer_ = std::make_unique<tf2_ros::Buffer>();
    listener_ = std::make_unique<tf2_ros::TransformListener>(*buffer_, nh);
  }
  if (!options_.mount.empty()) {
    const std::optional<double> taped =
        std::isfinite(options_.height) ? std::optional<double>(options_.height) : std::nullopt;
    head_ = BelieveHead(HeadModel::kPtu46, ReadMountFile(options_.mount), options_.mount, taped);
  }
}

CameraMountSource::~CameraMountSource() = default;

void CameraMountSource::OnJoints(const sensor_msgs::JointState& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  // A message may carry one of the joints: the other keeps its last angle.
  StampedHeadAngles reading =
      joints_.empty() ? StampedHeadAngles{0.0, 0.0, options_.tilt} : joints_.back();
  reading.t = msg.header.stamp.toSec();
  bool named = false;
  for (size_t i = 0; i < msg.name.size() && i < msg.position.size(); ++i) {
    if (!options_.pan_joint.empty() && msg.name[i] == options_.pan_joint) {
      reading.pan = msg.position[i];
      named = true;
    } else if (!options_.tilt_joint.empty() && msg.name[i] == options_.tilt_joint) {
      reading.tilt = msg.position[i];
      named = true;
    }
  }
  if (!named) return;
  if (!joints_.empty() && reading.t < joints_.back().t) joints_.clear();  // time went back
  joints_.push_back(reading);
  const double oldest = joints_.back().t - kJointHistoryS;
  joints_.erase(joints_.begin(),
                std::find_if(joints_.begin(), joints_.end(),
                             [&](const StampedHeadAngles& r) { return r.t >= oldest; }));
  joints_arrived_.notify_all();
}

std::optional<CameraMount> CameraMountSource::FromJoints(double t, std::string* why) {
  std::unique_lock<std::mutex> lock(mutex_);
  joints_arrived_.wait_for(lock, std::chrono::duration<double>(options_.wait),
                           [&] { return !joints_.empty() && joints_.back().t >= t; });
  const std::optional<StampedHeadAngles> angles = HeadAnglesAt(joints_, t, options_.max_gap);
  if (!angles) {
    *why = "no joint_states of " + options_.pan_joint + " " + options_.tilt_joint + " within " +
           std::to_string(options_.max_gap) + " s of the image's stamp";
    return std::nullopt;
  }
  CameraMount mount = Fixed();
  if (head_) {
    mount = MountOnHead(head_->geometry, head_->crossing_height, angles->pan, angles->tilt);
  } else {
    mount.pan = angles->pan;
    mount.tilt = angles->tilt;
  }
  if (!mount.Check(why)) {
    *why = "joint_states of " + options_.pan_joint + " " + options_.tilt_joint + ": " + *why;
    return std::nullopt;
  }
  return mount;
}

CameraMount CameraMountSource::Fixed() const {
  CameraMount mount;
  mount.height = options_.height;
  mount.tilt = options_.tilt;
  return mount;
}

std::optional<CameraMount> CameraMountSource::At(const std_msgs::Header& image, std::string* why) {
  const HeadSource source = options_.Resolved();
  std::optional<CameraMount> mount;
  std::string used = "fixed";
  if (source == HeadSource::kJointStates) {
    mount = FromJoints(image.stamp.toSec(), why);
    used = "joint_states";
  } else if (source == HeadSource::kFixed) {
    mount = Fixed();
  } else {
    const std::string& frame =
        options_.camera_frame.empty() ? image.frame_id : options_.camera_frame;
    // `auto` falls back on the fixed mount only while TF does not link the two frames at all.
    const bool linked =
        !frame.empty() && buffer_->canTransform(options_.base_frame, frame, ros::Time(0));
    if (source == HeadSource::kAuto && !linked && std::isfinite(options_.height)) {
      mount = Fixed();
    } else if (frame.empty()) {
      *why = "the image has no frame_id: give --camera-frame (~camera_frame)";
    } else {
      mount = FromTf(frame, image.stamp, why);
      used = "tf";
    }
  }
  if (!mount) return std::nullopt;
  std::lock_guard<std::mutex> lock(mutex_);
  last_source_ = used;
  return mount;
}

std::optional<CameraMount> CameraMountSource::FromTf(const std::string& frame,
                                                     const ros::Time& stamp, std::string* why) {
  const std::string link = "TF " + options_.base_frame + " -> " + frame;
  geometry_msgs::TransformStamped t;
  try {
    if (buffer_->canTransform(options_.base_frame, frame, stamp, ros::Duration(options_.wait))) {
      t = buffer_->lookupTransform(options_.base_frame, frame, stamp);
    } else {  // as the odometry: the latest reading, when near enough the stamp
      t = buffer_->lookupTransform(options_.base_frame, frame, ros::Time(0));
      const double gap = std::abs((t.header.stamp - stamp).toSec());
      if (!t.header.stamp.isZero() && gap > options_.max_gap) {
        *why = link + ": none at the image's stamp, the latest " + std::to_string(gap) + " s away";
        return std::nullopt;
      }
    }
  } catch (const tf2::TransformException& e) {
    *why = link + ": " + e.what();
    return std::nullopt;
  }
  const CameraMount mount = MountOfBaseFromCamera(ToIsometry(t.transform));
  if (!mount.Check(why) || std::abs(mount.roll) > options_.max_roll) {
    *why = link + ": tilt " + std::to_string(RadToDeg(mount.tilt)) + " deg, roll " +
           std::to_string(RadToDeg(mount.roll)) +
           " deg; linetrack needs a level camera looking forward: is " + frame +
           " the optical frame (z forward, x right, y down; REP 103)?";
    return std::nullopt;
  }
  return mount;
}

std::string CameraMountSource::LastSource() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_source_;
}

}  // namespace linetrack::app

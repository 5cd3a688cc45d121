// Recordings `replay` reads besides videos and image sequences: a robot's run with its frames,
// their stamps and the robot's readings (rosbag files, app/ros/). The binary hands `replay` the
// function that opens them; app/ itself knows no recording format.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/head_mount.h"
#include "models/camera.h"
#include "models/trajectory_io.h"
#include "tracking/capture/frame_source.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack::app {

// Which parts of the recording to read, and the camera's mount when no joint says it.
struct RecordingOptions {
  std::string image_topic, odom_topic, camera_info_topic, joint_states_topic;
  std::string pan_joint = "pan", tilt_joint = "tilt";  // names in the joint states
  double height = 0.0;                                 // camera above the base's origin (m)
  double tilt = 0.0;                                   // radians, without a tilt joint
  std::optional<Pose3Dof> start;  // the base's pose in the map at the first frame (--prior)
  // The camera on a calibrated pan-tilt head (--mount): its mount from the joint angles
  // (MountOnHead), `height` unused; none: the optical centre at `height` on the pan axis.
  std::optional<BelievedHead> head;
  std::string out_bag;  // poses and map -> odom written here (empty: none)
};

class Recording {
 public:
  virtual ~Recording() = default;
  // The frames, stamped with the recording's stamps (seconds).
  virtual FrameSource& frames() = 0;
  virtual long FrameCount() const = 0;
  virtual double FrameRate() const = 0;  // from the frames' stamps
  // The odometry as a prior file: the camera's reading at each odometry stamp (base pose moved
  // into the map, head angles, height); empty without odometry.
  virtual const std::vector<PriorRecord>& priors() const = 0;
  // The camera of the recording's camera_info, when one was asked for.
  virtual std::optional<CameraIntrinsics> camera() const = 0;
  // One replayed frame (poses for the output recording, when there is one).
  virtual void Add(double t, const FrameReport& report) = 0;
  // Completes the output recording (written to a temporary name until then).
  virtual void Finish() = 0;
};

// Opens `path` (checked whole before anything is written; throws InputError naming the file or
// topic for a bad recording).
using RecordingOpener =
    std::function<std::unique_ptr<Recording>(const std::string& path, const RecordingOptions&)>;

}  // namespace linetrack::app

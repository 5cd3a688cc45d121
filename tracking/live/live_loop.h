// The live loop of `linetrack live`: grab a frame, read the head, estimate the camera pose
// (CameraPoseEstimator, with the robot's prior: heading = base heading + pan, tilt from the
// head), servo the head to keep the target at the chosen pixel, and stop the head safely whenever
// there is no frame, no pose or no answer. One Step() per frame; the caller owns the timing.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/occlusion.h"
#include "models/wireframe.h"
#include "tracking/capture/frame_source.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/head/pan_tilt_head.h"
#include "tracking/live/pose_estimator.h"
#include "tracking/servo/head_servo.h"

namespace linetrack {

// The robot base's planar pose (x, y, base heading) believed at time t: odometry, a prior file,
// or a fixed prior for a robot standing still.
using BaseOdometry = std::function<Pose3Dof(double t)>;

// Length-weighted centroid of the visible parts of the model's edges seen from `cam_from_world`
// with `camera` (undistorted model with its size): a world point; empty when no edge is visible.
std::optional<Eigen::Vector3d> VisibleModelCentroid(const WireframeModel& model,
                                                    const OcclusionTester& occlusion,
                                                    const Eigen::Isometry3d& cam_from_world,
                                                    const CameraIntrinsics& camera);

struct LiveLoopOptions {
  HeadServoOptions servo;  // its geometry is also that of the camera prior
  // The servo's target in the world (metres); empty: the centroid of the visible model in the
  // first pose, fixed from then on.
  std::optional<Eigen::Vector3d> target;
  // Where the target should be in the (undistorted) image; empty: the principal point (u0, v0),
  // where the optical axis meets the image.
  std::optional<Eigen::Vector2d> desired_px;
  double crossing_height = 1.3;  // height of the head's axes above the floor (metres)

  bool Check(std::string* why) const;
};

// What the loop sent to the head on one iteration.
enum class HeadCommand {
  kNone,      // nothing sent (the same command as before, or the head did not answer)
  kVelocity,  // servo rates
  kHold,      // zero rates: converged
  kStop,  // safe stop: no frame (or one of the wrong size), no pose, no target, no head reading,
          // a refused command
};

// "none", "velocity", "hold", "stop".
const char* ToString(HeadCommand command);

// One iteration, as the head log (frames.csv) records it.
struct LiveIteration {
  std::int64_t frame = -1;  // index of the frame from the source (-1 without a frame)
  double t = 0.0;           // frame timestamp (seconds)
  FrameStatus grab = FrameStatus::kOk;
  bool head_read = false;  // the head answered Read()
  HeadState head;          // angles when the frame was processed
  RobotPose camera_prior;  // the matcher's prior for this frame
  PoseEstimate estimate;
  bool has_target = false;
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // world
  ServoStep servo;
  HeadCommand command = HeadCommand::kNone;
  HeadResult command_result;  // of the command finally sent
  bool head_error = false;    // a head call failed on this iteration (read or command)
  std::string note;           // why the head was stopped (empty otherwise)
  double grab_ms = 0.0;
  double estimate_ms = 0.0;
  double loop_ms = 0.0;  // everything after the grab: head read, estimate, servo, command
};

// What the loop runs on: the frames, the head, the pose estimate and the base's odometry (not
// owned; they must outlive the loop).
struct LiveLoopParts {
  FrameSource* source = nullptr;
  PanTiltHead* head = nullptr;
  CameraPoseEstimator* estimator = nullptr;
  BaseOdometry odometry;
};

class LiveLoop {
 public:
  // `model` must outlive the loop. `camera` is the undistorted model of the frames (the poses
  // project with it). Throws InputError on invalid options.
  LiveLoop(LiveLoopParts parts, const WireframeModel& model, const CameraIntrinsics& camera,
           const LiveLoopOptions& options);

  // Grabs one frame and acts on it. Returns what happened; `grab` kEndOfStream means no more.
  LiveIteration Step();

  // Stops the head (at the end of a run, on a signal). Safe to call any time.
  HeadResult SafeStop();

  const std::optional<Eigen::Vector3d>& target() const { return target_; }
  Eigen::Vector2d desired_px() const { return desired_px_; }
  const Frame& last_frame() const { return frame_; }

 private:
  // Sends a stop unless the head is already stopped; records it in *it.
  void StopHead(const std::string& why, LiveIteration* it);
  void Command(const ServoStep& step, LiveIteration* it);

  FrameSource* source_;
  PanTiltHead* head_;
  CameraPoseEstimator* estimator_;
  BaseOdometry odometry_;
  const WireframeModel& model_;
  OcclusionTester occlusion_;
  CameraIntrinsics camera_;
  LiveLoopOptions options_;
  HeadGeometry geometry_;
  HeadLimits limits_;
  HeadServo servo_;
  std::optional<Eigen::Vector3d> target_;
  Eigen::Vector2d desired_px_;
  Frame frame_;
  bool stopped_ = false;  // the last command left the head still (stop or hold)
};

// Counters over a run, for summary.json.
struct LiveSummary {
  std::int64_t iterations = 0, frames = 0, timeouts = 0, device_lost = 0;
  std::int64_t with_pose = 0, without_pose = 0;
  std::int64_t losses = 0, recoveries = 0;  // pose -> none, none -> pose (after a first pose)
  std::int64_t head_errors = 0;             // failed reads or commands
  std::int64_t converged_frames = 0, saturated_frames = 0, limited_frames = 0, stops = 0;
  double first_convergence_t = -1.0;             // time of the first converged frame (-1: never)
  double final_error_px = -1.0;                  // error of the last frame with a pose (-1: none)
  double max_error_after_convergence_px = -1.0;  // over frames with a pose after the first
  double max_abs_pan_rate = 0.0, max_abs_tilt_rate = 0.0;               // commanded (rad/s)
  double pan_min = 0.0, pan_max = 0.0, tilt_min = 0.0, tilt_max = 0.0;  // angles seen (rad)
  std::vector<double> loop_ms;  // per iteration with a frame, capture excluded
  double start_t = 0.0, last_t = 0.0;
  bool in_loss = false;  // no pose since the last frame with one

  // Counts one iteration.
  void Add(const LiveIteration& it);
};

}  // namespace linetrack

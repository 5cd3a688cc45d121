// What `linetrack live` runs on, built from checked flags and loaded files: the simulator (camera,
// head and true poses in one rig) or real devices (a frame source spec, a pan-tilt head spec),
// the pose estimator (the tracker, or the simulator's truth) and the live loop.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibration/mount_file.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/trajectory_io.h"
#include "models/wireframe.h"
#include "tracking/capture/frame_source.h"
#include "tracking/head/pan_tilt_head.h"
#include "tracking/live/live_loop.h"
#include "tracking/live/tracker_estimator.h"
#include "tracking/sim/sim_rig.h"

namespace linetrack::app {

// The command's flags, checked (angles in radians).
struct LivePlan {
  std::string source_spec, head_spec;
  bool sim = false;
  SimCameraOptions sim_camera;  // sim only
  HeadModel head_model = HeadModel::kPtu46;
  // Camera height with the head level (metres); none: the --mount file's floor calibration.
  std::optional<double> height;
  std::optional<Pose3Dof> prior;  // the robot base (x, y, heading)
  LiveLoopOptions loop;
  std::optional<Eigen::Vector2d> head_start, head_start_offset;
  bool use_tracker = true;  // false: the simulator's truth
  double camera_fps = 0.0;  // Aravis cameras: frame rate to set (0: keep the camera's)
  double duration = 0.0;    // seconds (simulated for sim); 0: until stopped
};

// The files the run needs, loaded and checked.
struct LiveInputs {
  CameraIntrinsics camera;  // of the frames, with its size and distortion
  const WireframeModel* model = nullptr;
  const NavigableArea* area = nullptr;  // for the tracker's matcher and the simulated loop
  std::vector<PriorRecord> priors;      // --prior-file: base odometry (t from the first frame)
  TrackerEstimatorOptions tracker;
  std::optional<MountFile> mount;  // --mount: the calibrated mount instead of the nominal one
  std::string mount_path;
};

// The base pose of `priors` at time t (seconds from the first frame): the last row at or before
// t, within 1 ms (the first row before it). Throws InputError when `priors` is empty.
Pose3Dof PriorAt(const std::vector<PriorRecord>& priors, double t);

class LiveSession {
 public:
  // Builds the estimator and opens the devices (real heads are moved to their start angles and
  // waited for). Throws InputError for bad specs or devices that cannot be opened,
  // std::runtime_error when a device does not answer.
  LiveSession(const LivePlan& plan, const LiveInputs& inputs);
  ~LiveSession();

  LiveLoop& loop() { return rig_ ? rig_->loop() : *loop_; }
  std::string DescribeSource() const;
  std::string DescribeHead() const;
  std::string DescribeEstimator() const;
  // The head geometry the loop believes (nominal or calibrated, and where its height came from).
  const std::string& DescribeMount() const { return mount_; }
  // Simulation: the true camera pose of the last frame; null for real devices.
  const Eigen::Isometry3d* truth() const;

 private:
  void OpenDevices(const LivePlan& plan, const LiveLoopOptions& loop, const LiveInputs& inputs);

  std::unique_ptr<TrackerPoseEstimator> tracker_;
  std::unique_ptr<SimulatedLiveRig> rig_;  // simulation
  std::unique_ptr<FrameSource> source_;    // real devices
  std::unique_ptr<PanTiltHead> head_;
  std::unique_ptr<LiveLoop> loop_;
  std::string mount_;
};

}  // namespace linetrack::app

// The simulator wired the way `linetrack live --source sim --head sim` wires it: the simulated
// head, the simulated camera on it, the simulator-truth pose estimator and the live loop. Used by
// the command, its benchmark and the closed-loop tests.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"
#include "tracking/live/live_loop.h"
#include "tracking/sim/sim_camera.h"
#include "tracking/sim/simulated_head.h"

namespace linetrack {

// Where the simulated head starts: its options' initial angles, or `offset` (pan, tilt radians)
// away from the angles that centre the loop's target seen from the base at t = 0.
struct SimHeadStart {
  std::optional<Eigen::Vector2d> offset_from_target;
};

// `loop` believing the nominal geometry of the simulated head model and the crossing height that
// geometry gives for the simulated camera's height (a height taped with the head level).
LiveLoopOptions NominalBelief(const SimCameraOptions& camera, LiveLoopOptions loop);

// The settings of the rig's parts.
struct SimulatedLiveRigOptions {
  SimCameraOptions camera;
  SimulatedHeadOptions head;
  LiveLoopOptions loop;
  SimHeadStart start;
  PoseJitterOptions jitter;  // of the simulator's truth, when it is the estimator
};

class SimulatedLiveRig {
 public:
  // `camera` is the camera of the frames (its undistorted model serves the loop); `model` and
  // `area` must outlive the rig. The loop believes options.loop (the servo's geometry and the
  // crossing height, e.g. NominalBelief), whatever the simulated camera's truth.
  // `estimator` gives the poses (not owned; e.g. the tracker); null: the simulator's truth,
  // jittered by options.jitter. Throws InputError on invalid options, or when an offset start is
  // asked without a target or the target cannot be looked at.
  SimulatedLiveRig(const WireframeModel& model, const NavigableArea* area,
                   const CameraIntrinsics& camera, const SimulatedLiveRigOptions& options,
                   CameraPoseEstimator* estimator = nullptr);

  SimulatedCamera& camera() { return camera_; }
  SimulatedHead& head() { return *head_; }
  LiveLoop& loop() { return *loop_; }
  CameraPoseEstimator& estimator() { return *estimator_; }

  // Distance in pixels of the loop's target from its desired pixel in the last frame, from the
  // true pose (undistorted image); -1 before the loop has a target.
  double TrueErrorPx() const;

 private:
  CameraIntrinsics undistorted_;
  SimulatedCamera camera_;
  std::unique_ptr<SimulatedHead> head_;
  std::unique_ptr<SimulatorTruthEstimator> truth_;
  CameraPoseEstimator* estimator_ = nullptr;
  std::unique_ptr<LiveLoop> loop_;
};

}  // namespace linetrack

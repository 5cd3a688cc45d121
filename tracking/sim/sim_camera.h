// The simulated camera on the simulated head (`--source sim --head sim`): a robot base standing
// still or driving a loop through the model, the simulated head on it, and the renderer
// (models/render/) drawing what the camera sees: camera pose = base pose x BaseFromCamera(pan,
// tilt) (head_pointing.h), so the servo's commands change the next frame. Time is simulated: each
// Grab() advances the head by one frame period (no sleeping); deterministic for a seed.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/wireframe.h"
#include "tracking/capture/frame_source.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/live/pose_estimator.h"
#include "tracking/sim/simulated_head.h"

namespace linetrack {

enum class SimPath {
  kStill,  // the base stands at SimCameraOptions::still_base
  kLoop,   // the base drives the loop of LoopInsideArea (counter-clockwise, laps repeat)
};

struct SimCameraOptions {
  SimPath path = SimPath::kStill;
  double fps = 30.0;           // frames per simulated second
  double speed = 0.5;          // loop: metres per second
  double wall_distance = 1.0;  // loop: metres kept from walls and obstacles
  Pose3Dof still_base;         // still: the base's x, y and heading (radians)
  double camera_height = 1.3;  // camera centre above the floor with the head level (metres)
  HeadModel head_model = HeadModel::kPtu46;
  // How far the simulated bracket is off the head model's nominal mount: (shift in metres,
  // rotation vector in radians), both in the tilt frame (MovedPose, models/pan_tilt.h).
  Eigen::Matrix<double, 6, 1> bracket_error = Eigen::Matrix<double, 6, 1>::Zero();
  // Lens capped from cap_from_s to cap_to_s (simulated seconds): black frames, the way to force
  // a loss of tracking. Off when cap_to_s <= cap_from_s.
  double cap_from_s = 0.0, cap_to_s = 0.0;
  // false: frames are uniform grey instead of rendered (closed-loop tests fed with the true pose,
  // where the pixels are not looked at). Capped frames are black either way.
  bool render = true;
  RenderOptions render_options;  // seed, clutter, noise, blur
  uint64_t odometry_seed = 1;    // loop: the simulated odometry's noise (SimulateOdometryPriors)

  bool Check(std::string* why) const;
};

// Reads the text after "sim:" into `options` (fields not named keep their values):
// comma-separated key=value with keys path (still|loop), fps, speed, seed, clutter, noise, blur,
// cap (T0-T1 seconds), render (0|1), bracket_mm (X:Y:Z shift) and bracket_deg (RX:RY:RZ rotation
// vector) of the bracket's error. Throws InputError naming "--source sim:ARGS" and the key.
void ParseSimArguments(const std::string& arguments, SimCameraOptions* options);

// The simulated camera. Steps the simulated head attached to it: the head must outlive it and
// nothing else may step it.
class SimulatedCamera : public FrameSource {
 public:
  // `area` is needed for the loop path (may be null for kStill). Throws InputError on invalid
  // options, a camera without image size, or a loop that does not fit the area. The head is
  // attached afterwards (its start angles may depend on BaseAt(0)).
  SimulatedCamera(const WireframeModel& model, const NavigableArea* area,
                  const CameraIntrinsics& camera, const SimCameraOptions& options);
  ~SimulatedCamera() override;

  // The head the camera sits on (not owned): the simulated head, stepped by the camera.
  void AttachHead(SimulatedHead* head);
  // Any head whose clock `advance` moves forward by the given seconds (the PTU emulator behind a
  // PtuDriver, for instance); the camera reads the head's angles through Read().
  void AttachHead(PanTiltHead* head, std::function<void(double)> advance);

  // Frame k is taken at t = k / fps: the head is stepped to t, read, and the view rendered.
  // kDeviceLost while no head is attached or when it cannot be read (LastError says why).
  FrameStatus Grab(Frame* frame) override;
  std::string LastError() const override;
  std::string Describe() const override;
  SourceStats Stats() const override { return stats_; }

  // The robot base's true planar pose at time t (x, y, heading of the base).
  Pose3Dof BaseAt(double t) const;
  // What the robot's odometry says at time t: exact when standing still, simulated odometry
  // (drift and noise from odometry_seed) on the loop.
  Pose3Dof OdometryAt(double t) const;
  // Height of the pan and tilt axes' crossing above the floor.
  double crossing_height() const { return crossing_height_; }
  // The true geometry: the head model's nominal mount moved by the bracket's error.
  const HeadGeometry& geometry() const { return geometry_; }
  bool CappedAt(double t) const;

  // Ground truth of the last frame grabbed: its time, the head angles it was rendered with and
  // the camera pose (cam_from_world).
  double last_time() const { return last_time_; }
  const Eigen::Isometry3d& last_cam_from_world() const { return last_cam_from_world_; }
  double last_pan() const { return last_pan_; }
  double last_tilt() const { return last_tilt_; }
  bool last_capped() const { return last_capped_; }

 private:
  int LoopIndexAt(double t) const;

  SimCameraOptions options_;
  CameraIntrinsics camera_;
  PanTiltHead* head_ = nullptr;
  std::function<void(double)> advance_head_;
  HeadGeometry geometry_;
  double crossing_height_ = 0.0;
  std::unique_ptr<SceneRenderer> renderer_;  // null when not rendering
  std::vector<Pose3Dof> loop_bases_;         // one lap, one per frame
  std::vector<Pose3Dof> loop_odometry_;
  std::int64_t next_index_ = 0;
  std::int64_t head_clock_index_ = 0;  // the frame the head's clock has been advanced to
  SourceStats stats_;
  double last_time_ = 0.0;
  Eigen::Isometry3d last_cam_from_world_ = Eigen::Isometry3d::Identity();
  double last_pan_ = 0.0, last_tilt_ = 0.0;
  bool last_capped_ = false;
  std::string last_error_;
};

}  // namespace linetrack

namespace linetrack {

// Optional jitter of the simulator's truth, standing in for a tracker's frame-to-frame noise.
struct PoseJitterOptions {
  double rotation_sigma = 0.0;     // radians, per axis of a small rotation (camera frame)
  double translation_sigma = 0.0;  // metres, per axis
  uint64_t seed = 1;

  bool Check(std::string* why) const;
};

// A pose estimator that returns the simulator's true camera pose (no pose while the lens is
// capped), optionally jittered. For developing and testing the servo and the live loop without
// the tracker; it does not look at the pixels, so it is not tracking.
class SimulatorTruthEstimator : public CameraPoseEstimator {
 public:
  // Throws InputError on invalid jitter options.
  explicit SimulatorTruthEstimator(const SimulatedCamera* camera,
                                   const PoseJitterOptions& jitter = {});
  PoseEstimate Estimate(const Frame& frame, const HeadState& head,
                        const RobotPose& camera_prior) override;
  std::string Describe() const override { return "simulator truth (not tracking)"; }

 private:
  const SimulatedCamera* camera_;
  PoseJitterOptions jitter_;
  std::mt19937_64 rng_;
  bool had_pose_ = false;
  bool lost_ = false;
};

}  // namespace linetrack

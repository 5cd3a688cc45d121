// Benchmark of the live loop on the simulator (`linetrack bench servo`): the time of one loop
// iteration excluding capture (head read, pose estimate, servo law, head command), and the
// servo's accuracy: convergence from a 10 deg pan / 5 deg tilt offset with the robot standing
// still, and the target's distance from the centre while the robot drives one lap of the loop.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/wireframe.h"
#include "tracking/live/tracker_estimator.h"
#include "tracking/servo/head_servo.h"
#include "tracking/sim/sim_camera.h"

namespace linetrack::app {

struct ServoBenchOptions {
  double fps = 30.0;            // simulated frame rate
  double still_seconds = 5.0;   // convergence run (robot standing still)
  double drive_seconds = 76.0;  // driving run: one lap of the hall loop at 0.5 m/s
  double settle_seconds = 2.0;  // start of the driving run left out of its error figures
  bool render = true;           // render the frames (not timed), as the live command does
  Pose3Dof still_base{3.0, 1.5, 0.3490658503988659};  // (3, 1.5) m, heading 20 deg
  Eigen::Vector3d still_target{9.25, 2.75, 1.5};      // a pillar corner seen from there
  Eigen::Vector3d drive_target{7.0, 4.5, 1.2};        // between the pillars
  double start_pan_offset = 0.17453292519943295;      // 10 deg
  double start_tilt_offset = 0.08726646259971647;     // 5 deg
  HeadServoOptions servo;
  // The poses: the tracker (rendered frames needed), or the simulator's truth with `jitter`
  // standing in for a tracker's noise.
  bool use_tracker = true;
  TrackerEstimatorOptions tracker;
  PoseJitterOptions jitter;

  bool Check(std::string* why) const;
};

// One run of the benchmark.
struct ServoBenchRun {
  std::string name;  // "still" or "drive"
  int frames = 0;
  double start_error_px = 0.0;  // true error on the first frame
  double convergence_s = -1.0;  // first frame whose true error is below 2 px (-1: never)
  double final_error_px = 0.0;  // true error on the last frame
  double settle_s = 0.0;        // the statistics below leave out the frames before this
  double mean_error_px = 0.0;   // true error over the frames after settle_seconds
  double p95_error_px = 0.0;
  double max_error_px = 0.0;
  std::vector<double> loop_ms;      // per iteration, capture excluded
  std::vector<double> estimate_ms;  // of which the pose estimate
  int frames_with_pose = 0;
  double max_position_error_m = 0.0;  // estimated pose against the truth (frames with a pose)
  double max_rotation_error_deg = 0.0;
  std::vector<double> grab_ms;  // capture (rendering), not in loop_ms
  // With the tracker, its stages per frame (FrameReport): undistortion, odometry prediction,
  // ViSP's passes, measurement and refinement, re-localisation; and the passes run.
  std::vector<double> undistort_ms, predict_ms, passes_ms, measure_ms, relocalize_ms;
  int tracking_passes = 0;
};

// Runs both scenarios on `model` with `camera` (its size is the frame size). `area` is needed
// for the loop. Throws InputError on invalid options.
std::vector<ServoBenchRun> RunServoBench(const WireframeModel& model, const NavigableArea& area,
                                         const CameraIntrinsics& camera,
                                         const ServoBenchOptions& options);

}  // namespace linetrack::app

// The views of `linetrack calibrate-mount` in its live mode: the head is driven through a grid of
// angles (tracking/head/head_sweep.h) and one frame is kept at each, with the head's reading.
// Real devices (--source aravis|v4l2, --head ptu:DEV) or the simulator (--source sim[:ARGS]
// --head sim): the simulated camera on the simulated head, the robot standing still, a chessboard
// standing in front of the head, optionally the simulated bracket off (sim:bracket_mm=...,
// bracket_deg=...; tracking/sim/sim_camera.h).
#pragma once

#include <opencv2/core/mat.hpp>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/mount_calibration.h"
#include "calibration/pattern.h"
#include "models/camera.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/head/head_sweep.h"

namespace linetrack::app {

struct MountViewsPlan {
  std::string source_spec, head_spec;
  std::vector<Eigen::Vector2d> angles;  // pan, tilt (radians) to visit
  HeadSweepOptions sweep;
  // The simulator only.
  HeadModel head_model = HeadModel::kPtu46;
  double camera_height = 1.3;   // the simulated camera above the floor, head level (metres)
  double board_distance = 1.0;  // the board's centre from the camera at the grid's centre (m)
  Eigen::Vector2d grid_centre = Eigen::Vector2d::Zero();
  std::string model_path;  // the scene around (empty: floor and ceiling only)
};

struct MountViews {
  std::vector<std::string> names;  // view_01.png, ...
  std::vector<cv::Mat> images;     // 8-bit grey, the camera's size
  std::vector<HeadAngles> angles;  // the head's readings
  std::string source, head;        // descriptions for the log
  // The camera's distortion in these images: the simulator draws the inverse of kdu.
  DistortionModel distortion = DistortionModel::kKud;
};

// The chessboard in the simulated world: centred `distance` metres along the optical axis of the
// nominal camera at `angles` (base standing at the origin, heading 0), facing it, turned 15 deg
// about the vertical and 10 deg about its rows so that it is not seen square on.
Eigen::Isometry3d SimulatedBoardPose(const PatternSpec& pattern, const HeadGeometry& nominal,
                                     double crossing_height, const Eigen::Vector2d& angles,
                                     double distance);

// Opens the devices (or builds the simulator), sweeps the head and returns the views. Throws
// InputError for bad specs or devices that cannot be opened, std::runtime_error when the sweep
// fails (a device that stops answering, a head that does not settle).
MountViews GrabMountViews(const MountViewsPlan& plan, const PatternSpec& pattern,
                          const CameraIntrinsics& camera);

}  // namespace linetrack::app

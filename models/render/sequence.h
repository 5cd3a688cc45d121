// Camera sequences for synthetic tests and demos: a smooth closed loop through the navigable
// area, a robot driving along it at a known height with an optional pan-tilt head, and the
// odometry-like priors (noisy, drifting) a localiser would get.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "models/navigable_area.h"
#include "models/robot_pose.h"
#include "models/trajectory_io.h"

namespace linetrack {

struct LoopPathOptions {
  double wall_distance = 1.0;  // metres kept from the area's boundary, walls and obstacles
  double smoothing = 0.75;     // metres: std of the Gaussian smoothing along the loop
  double step = 0.05;          // metres between loop points (and cell of the distance grid)

  bool Check(std::string* why) const;
};

// A smooth closed loop inside `area`: the outer contour of the points at least `wall_distance`
// from the area's boundary, holes and walls, smoothed along its length; counter-clockwise,
// sampled every `step` metres (the first point is not repeated). Every point is checked with
// area.Contains(); throws InputError naming the area's source when no loop fits.
std::vector<Eigen::Vector2d> LoopInsideArea(const NavigableArea& area,
                                            const LoopPathOptions& options = {});

// One frame of a sequence.
struct SequenceFrame {
  double t = 0.0;    // seconds
  RobotPose base;    // the robot: position, heading of the base, camera height; tilt 0
  double pan = 0.0;  // head pan (radians, counter-clockwise from the base heading)
  RobotPose camera;  // the camera: heading = base heading + pan, tilt = head tilt
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
};

struct DriveOptions {
  double speed = 0.5;           // metres per second along the loop
  double fps = 10.0;            // frames per second
  int frames = 0;               // number of frames; 0: one lap
  double height = 1.3;          // camera height (metres)
  double tilt = 0.0872664626;   // mean head tilt (radians, positive down; default 5 deg)
  double tilt_amplitude = 0.0;  // sinusoidal tilt offset (radians)
  double tilt_period = 11.0;    // seconds
  double pan_amplitude = 0.0;   // sinusoidal pan offset (radians)
  double pan_period = 8.0;      // seconds

  bool Check(std::string* why) const;
};

// A robot driving forward along `loop` (from its first point, counter-clockwise) at constant
// speed; the base heading is the loop's tangent; pan(t) = A sin(2 pi t / T_pan),
// tilt(t) = tilt + B sin(2 pi t / T_tilt).
std::vector<SequenceFrame> DriveAlongLoop(const std::vector<Eigen::Vector2d>& loop,
                                          const DriveOptions& options);

// Frames of a TUM trajectory (world_from_cam): the camera poses as given; the base is the
// camera's position and heading (pan 0), its tilt read from the optical axis.
std::vector<SequenceFrame> FramesFromTrajectory(const std::vector<StampedPose>& poses);

struct OdometryOptions {
  uint64_t seed = 1;
  double distance_noise = 0.02;  // relative std of each distance increment
  double heading_noise = 0.02;   // relative std of each heading increment
  double heading_walk = 0.005;   // std of heading noise per sqrt(metre) travelled (rad)
  double scale_bias = 0.01;      // std of the constant relative distance error (wheel radius)
  double heading_bias = 0.0087;  // std of the constant heading drift (radians per metre)

  bool Check(std::string* why) const;
};

// Odometry-like priors for `frames`: the base's motion between frames (distance, heading
// change, direction of travel relative to the heading) integrated from the true first pose with
// multiplicative noise on the increments and constant biases drawn once from the seed. The prior
// heading is the odometry heading + pan (head encoders exact); height and tilt are exact.
std::vector<PriorRecord> SimulateOdometryPriors(const std::vector<SequenceFrame>& frames,
                                                const OdometryOptions& options);

// The ground truth of `frames` as TUM poses (world_from_cam).
std::vector<StampedPose> GroundTruthPoses(const std::vector<SequenceFrame>& frames);

}  // namespace linetrack

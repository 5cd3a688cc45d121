// Camera sequences for synthetic tests and demos: a smooth closed loop through the navigable
// area (or a path through waypoints, waypoint_path.h), a robot driving along it at a known height
// with an optional pan-tilt head, and the odometry-like priors (noisy, drifting) a localiser
// would get.
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

// Base heading minus the path's direction (radians) at arc length s (metres).
struct HeadingKnot {
  double s = 0.0;
  double offset = 0.0;
};

// A path sampled at equal arc-length steps. A closed path wraps (its first point is not
// repeated); an open one runs from the first point to the last. The heading knots, when given,
// set the base heading's offset from the path's direction, linear in arc length between knots
// (sorted by s, offsets continuous; a closed path's last knot lies at its length); without
// knots the base heading is the path's direction.
struct SampledPath {
  std::vector<Eigen::Vector2d> points;
  std::vector<HeadingKnot> heading_knots;
  bool closed = true;
  double step = 0.0;  // metres between consecutive points

  // The path through `points` (at least two), its step their length over the segments.
  static SampledPath Through(std::vector<Eigen::Vector2d> points, bool closed);

  double Length() const;                    // metres, summed over the segments
  Eigen::Vector2d PointAt(double s) const;  // at arc length s: wraps (closed), clamps (open)
  double DirectionAt(double s) const;       // radians: the chord from s - 0.2 m to s + 0.2 m
  double HeadingOffsetAt(double s) const;   // radians; 0 without knots
};

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
  double pan_amplitude = 0.0;   // pan offset amplitude (radians)
  double pan_period = 8.0;      // seconds, of the sinusoidal pan
  double pan_rate = 0.0;        // rad/s: > 0 pans at this constant rate between +-amplitude

  bool Check(std::string* why) const;
};

// Head pan at time t (radians): A sin(2 pi t / T_pan), or with a pan rate w a triangle wave
// between -A and A of period 4 A / w starting at 0 towards +A.
double HeadPanAt(const DriveOptions& options, double t);

// A robot driving forward along `loop` (from its first point, counter-clockwise) at constant
// speed; the base heading is the loop's tangent; pan(t) = HeadPanAt(t),
// tilt(t) = tilt + B sin(2 pi t / T_tilt).
std::vector<SequenceFrame> DriveAlongLoop(const std::vector<Eigen::Vector2d>& loop,
                                          const DriveOptions& options);

// The same along any sampled path: the base heading is the path's direction (chord over
// +-0.2 m) plus its heading offset. A closed path repeats its laps; frames = 0 drives one lap
// (closed) or to the end (open). Throws InputError when an open path is too short for the
// asked frames.
std::vector<SequenceFrame> DriveAlongPath(const SampledPath& path, const DriveOptions& options);

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
  double scale_error = 0.0;      // fixed relative distance error, added to the drawn bias
  double heading_drift = 0.0;    // fixed heading drift (radians per metre), added to the drawn one

  bool Check(std::string* why) const;
};

// Odometry-like priors for `frames`: the base's motion between frames (distance, heading
// change, direction of travel relative to the heading) integrated from the true first pose with
// multiplicative noise on the increments and constant biases drawn once from the seed. The prior
// heading is the odometry heading + pan (head encoders exact); height and tilt are exact.
std::vector<PriorRecord> SimulateOdometryPriors(const std::vector<SequenceFrame>& frames,
                                                const OdometryOptions& options);

// Odometry for a stated drift share d of the distance travelled (e.g. 0.025): the distance scale
// is off by 0.9 d and the heading drifts by 0.02 d radians per metre, their signs drawn from the
// seed; increment noise as OdometryOptions' defaults, the heading walk 0.002 rad/sqrt(m).
OdometryOptions OdometryForDrift(double drift, uint64_t seed);

// How far odometry priors drift from the truth: over every window of `window_m` metres travelled
// (windows starting at each frame), the error of the odometry's motion expressed in the base
// frame at the window's start, |T_odo(a)^-1 T_odo(b) - T(a)^-1 T(b)| (translation), divided by
// the distance travelled (KITTI's relative translation error); and the same over the whole run.
struct OdometryDrift {
  double window_m = 0.0;
  double max_share = 0.0;    // largest over the windows
  double mean_share = 0.0;   // mean over the windows
  double whole_share = 0.0;  // first frame to last
  int windows = 0;
};
OdometryDrift MeasureOdometryDrift(const std::vector<SequenceFrame>& frames,
                                   const std::vector<PriorRecord>& priors, double window_m);

// The ground truth of `frames` as TUM poses (world_from_cam).
std::vector<StampedPose> GroundTruthPoses(const std::vector<SequenceFrame>& frames);

}  // namespace linetrack

// Coasting on the odometry through the frames the image cannot hold, the way a GNSS/INS integrity
// monitor coasts on its inertial unit (docs/integrity.md, section 5.1): the last reported pose is
// carried by the odometry's motion, its protection levels grow by a stated bound on the
// odometry's error and its covariance by the odometry's noise; an image pose and the coasted one
// that contradict each other (beyond the sum of their levels) mean one of them is faulty.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "models/robot_pose.h"
#include "tracking/integrity/integrity_monitor.h"

namespace linetrack {

// The camera pose now from the last pose and the robot's readings then and now (odometry position
// and heading, height, tilt, roll): C_now C_then^-1 last, with C = CamFromWorld of a reading.
// Keeps the last pose's own small errors; only the relative motion of the odometry is used.
Eigen::Isometry3d PredictFromOdometry(const Eigen::Isometry3d& last, const RobotPose& then,
                                      const RobotPose& now);

// The odometry's stated error bound (`--odometry-bound SHARE,DEG_PER_M,TURN_SHARE`) over each
// step of driving: `step` metres (the odometry's own count) and `turn` radians of change of the
// camera's heading (odometry and head pan): the step's translation, in the base frame at its
// start, is off by at most distance_share x step; its heading change by at most
// heading_per_m x step + turn_share x |turn| (the head encoders are exact).
struct OdometryBound {
  double distance_share = 0.15;
  double heading_per_m = 3.0 * kPi / 180.0;  // radians per metre
  double turn_share = 0.15;

  bool Check(std::string* why) const;
};

// Coasting: the odometry's bound, and the limits since the last image fix beyond which a coasted
// pose is lost (odometry distance, frames).
struct CoastOptions {
  bool enabled = true;
  OdometryBound bound;
  double max_distance_m = 2.0;
  int max_frames = 50;

  bool Check(std::string* why) const;
};

// Protection levels: horizontal position (metres) and heading (radians).
struct CoastLevels {
  double position_m = 0.0;
  double rotation_rad = 0.0;
};

// The levels after one odometry step of `step_m` metres and `turn_rad` radians of heading change,
// s, h, t the bound's shares (docs/integrity.md 5.1):
//   position' = position + s step + 2 sin(min(rotation, pi) / 2) (1 + s) step
//   rotation' = rotation + h step + t |turn|
// the heading error rotating the step's displacement (at most (1 + s) step long).
CoastLevels GrowCoastLevels(const CoastLevels& levels, double step_m, double turn_rad,
                            const OdometryBound& bound);

// The world-twist covariance (dC, omega; metres, radians) of a pose moved by the world
// displacement `displacement` of its camera centre: P' = J P J' + Q, J = [I -[d]x; 0 I] (a heading
// error rotates the displacement), Q the odometry's noise: the bound taken as 3 sigma and fully
// correlated along the stretch coasted, Q = diag((E'^2 - E^2) / 9) with E the bound's
// accumulated position (x, y) and heading errors before (`before`) and after (`after`) the step.
Eigen::Matrix<double, 6, 6> CarryCovariance(const Eigen::Matrix<double, 6, 6>& covariance,
                                            const Eigen::Vector3d& displacement,
                                            const CoastLevels& before, const CoastLevels& after);

// A reported pose the odometry may carry: the pose with its uncertainty (finite levels), the
// odometry's camera pose at its frame, and the stretch coasted since the last image fix.
struct CoastAnchor {
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  PoseUncertainty uncertainty;
  RobotPose odometry;     // the reading at the anchor's frame (with height, tilt, roll)
  long fix_frame = -1;    // the frame of the last image fix
  CoastLevels noise;      // the bound's accumulated errors since that fix (position, heading)
  double driven_m = 0.0;  // odometry distance since that fix
  int frames = 0;         // frames coasted since that fix
};

// The anchor's pose carried to the reading `now` (PredictFromOdometry): its levels grown step by
// step (GrowCoastLevels), its covariance (CarryCovariance), status tracking when both levels are
// within the alert limits, else degraded; lost beyond the coasting limits. `frame` is this frame.
struct CoastedPose {
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  PoseUncertainty uncertainty;
  CoastAnchor anchor;  // the anchor this pose becomes when it is reported
  std::string note;    // "odometry: 0.35 m since frame 123"
};
CoastedPose Coast(const CoastAnchor& anchor, const RobotPose& now, const CoastOptions& options,
                  const IntegrityOptions& alert);

// A new anchor at an image fix: `pose` with its uncertainty at frame `frame` and reading
// `odometry`.
CoastAnchor AnchorAtFix(const Eigen::Isometry3d& pose, const PoseUncertainty& uncertainty,
                        const RobotPose& odometry, long frame);

// How far apart two poses are (horizontal metres, heading radians), and whether that is beyond
// the sum of their protection levels: then one of them is faulty.
struct PoseDisagreement {
  double position_m = 0.0;
  double rotation_rad = 0.0;
  bool contradicts = false;
};
PoseDisagreement Disagreement(const Eigen::Isometry3d& a, const PoseUncertainty& ua,
                              const Eigen::Isometry3d& b, const PoseUncertainty& ub);

// The union of two contradicting bounds, reported about `reported`: the truth lies within the
// reported pose's own levels, or within the other's levels of the other pose, so within
// max(L_reported, separation + L_other) of the reported pose (each level); the covariance grows by
// the separation's square on x, y and heading. Status degraded, `why` the reason.
PoseUncertainty UnionOfContradicting(const PoseUncertainty& reported, const PoseUncertainty& other,
                                     const PoseDisagreement& disagreement, const std::string& why);

// Whether the coasted pose is reported rather than the image's (both valid bounds, union): only
// when it is within the alert limits and the image pose is not. Otherwise the image pose, fresh
// from this frame, is reported (a coasted level only grows: it never helps a later frame more).
bool PreferCoasted(const PoseUncertainty& image, const PoseUncertainty& coasted);

}  // namespace linetrack

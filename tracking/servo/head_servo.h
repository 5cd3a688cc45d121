// Visual servoing of a pan-tilt head on one image point: ViSP's vpServo in the eye-in-hand
// configuration EYEINHAND_L_cVe_eJe, q_dot = -lambda (L cVe eJe)^+ (s - s*), with a 2D point
// feature s = (x, y) (vpFeaturePoint, depth from the pose), the head's Jacobian
// (head_kinematics.h), ViSP's adaptive gain, an optional compensation of the target's own image
// motion, joint speed saturation, a slow-down near the joint limits and a hold at convergence.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>

#include "models/camera.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/head/pan_tilt_head.h"

namespace linetrack {

struct HeadServoOptions {
  // The camera on the head as the robot believes it: a head's nominal geometry (GeometryOf) or a
  // calibrated mount. It gives the servo's cVe and eJe.
  HeadGeometry geometry = GeometryOf(HeadModel::kPtu46);
  // vpAdaptiveGain: lambda(x) = (l0 - linf) exp(-slope x / (l0 - linf)) + linf, x = the joint
  // correction |J^+ e|_inf in radians (1/s; slope 1/(s rad)).
  double gain_at_zero = 8.0;
  double gain_at_infinity = 3.0;
  double gain_slope_at_zero = 30.0;
  // Saturation of the commanded joint rates (rad/s), scaling both rates together (the direction
  // of the correction is kept, vpRobot::saturateVelocities); the head's own maxima also apply.
  double max_pan_rate = 1.0;
  double max_tilt_rate = 1.0;
  // Hold (zero rates) once the image error is below convergence_px, unless the target is seen
  // moving faster than hold_max_target_speed_px_s (robot driving: holding would let it drift);
  // servo again when the error exceeds resume_px.
  double convergence_px = 0.5;
  double resume_px = 2.0;
  double hold_max_target_speed_px_s = 10.0;
  // A rate towards a joint limit is capped at (distance to the limit) / limit_horizon_s.
  double limit_horizon_s = 0.25;
  // Feed-forward of the target's image motion not caused by the head (robot driving), estimated
  // from consecutive errors and the measured joint motion, low-pass filtered with this weight of
  // the newest estimate (0: off).
  double target_motion_filter = 0.5;
  // Longest interval over which the target motion is estimated (s); longer gaps restart it.
  double target_motion_max_interval_s = 0.5;

  bool Check(std::string* why) const;
};

// One servo iteration.
struct ServoStep {
  bool ok = false;     // false: no command (reason says why); rates are then zero
  std::string reason;  // "target behind the camera", ViSP's message, ...
  double error_u_px = 0.0, error_v_px = 0.0;  // current minus desired pixel
  double error_px = 0.0;                      // Euclidean norm of the two
  double gain = 0.0;                          // lambda of this iteration (1/s)
  double pan_rate = 0.0, tilt_rate = 0.0;     // command sent to the head (rad/s)
  bool converged = false;                     // holding: error below the convergence threshold
  bool saturated = false;                     // the rates were scaled down to the maxima
  bool limited = false;                       // a rate was capped near a joint limit
  bool compensated = false;                   // the target-motion feed-forward was applied
  double target_speed_px_s = 0.0;  // estimated image speed of the target itself (0: unknown)
};

// Scales (pan_rate, tilt_rate) down together so that neither exceeds its maximum; *saturated
// tells whether it did.
Eigen::Vector2d SaturateJointRates(const Eigen::Vector2d& rates, double max_pan_rate,
                                   double max_tilt_rate, bool* saturated);

// Caps each rate moving towards a joint limit at (distance to that limit) / horizon_s (zero at
// or beyond the limit); rates moving away are kept. *limited tells whether a rate changed.
Eigen::Vector2d KeepWithinJointLimits(const Eigen::Vector2d& rates, double pan, double tilt,
                                      const HeadLimits& limits, double horizon_s, bool* limited);

// Image error of a target seen at `target_cam` (camera frame, metres, z > 0) against the desired
// pixel: projected pixel minus desired pixel (undistorted image).
Eigen::Vector2d PixelError(const CameraIntrinsics& camera, const Eigen::Vector3d& target_cam,
                           const Eigen::Vector2d& desired_px);

// Where the head's joints are (radians) and how far they may go.
struct HeadJoints {
  double pan = 0.0, tilt = 0.0;
  HeadLimits limits;
};

// The servo. Keeps ViSP's task between iterations (hold state, target-motion estimate).
// Not copyable (vpServo keeps pointers to its features).
class HeadServo {
 public:
  // Throws InputError when the options are invalid.
  explicit HeadServo(const HeadServoOptions& options);
  ~HeadServo();
  HeadServo(const HeadServo&) = delete;
  HeadServo& operator=(const HeadServo&) = delete;

  // One iteration at time t (seconds): the target at `target_cam` (camera frame, from the pose),
  // to be brought to `desired_px` of `camera` (undistorted model), the head as `head` says.
  // Never throws for ViSP failures (a result without command).
  ServoStep Compute(double t, const Eigen::Vector3d& target_cam, const Eigen::Vector2d& desired_px,
                    const CameraIntrinsics& camera, const HeadJoints& head);

  // Forgets the hold state and the target-motion estimate (after a loss of tracking).
  void Reset();

  const HeadServoOptions& options() const { return options_; }

 private:
  struct Impl;
  HeadServoOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack

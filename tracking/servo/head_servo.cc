#include "tracking/servo/head_servo.h"

#include <visp3/core/vpException.h>
#include <visp3/visual_features/vpFeaturePoint.h>
#include <visp3/vs/vpAdaptiveGain.h>
#include <visp3/vs/vpServo.h>

#include <algorithm>
#include <cmath>

#include "models/errors.h"

namespace linetrack {

bool HeadServoOptions::Check(std::string* why) const {
  if (!geometry.Check(why)) return false;
  if (!(gain_at_zero > 0.0 && gain_at_infinity > 0.0 && gain_at_infinity <= gain_at_zero &&
        gain_at_zero < 1e3)) {
    *why = "gains must satisfy 0 < gain at infinity <= gain at zero < 1000";
    return false;
  }
  if (!(gain_slope_at_zero >= 0.0 && std::isfinite(gain_slope_at_zero))) {
    *why = "gain slope at zero must be finite and >= 0";
    return false;
  }
  if (!(max_pan_rate > 0.0 && max_tilt_rate > 0.0 && max_pan_rate < 100.0 &&
        max_tilt_rate < 100.0)) {
    *why = "maximum joint rates must be in (0, 100) rad/s";
    return false;
  }
  if (!(convergence_px >= 0.0 && resume_px >= convergence_px && resume_px < 1e4)) {
    *why = "need 0 <= convergence_px <= resume_px";
    return false;
  }
  if (!(hold_max_target_speed_px_s >= 0.0 && std::isfinite(hold_max_target_speed_px_s))) {
    *why = "the hold's target speed must be finite and >= 0";
    return false;
  }
  if (!(limit_horizon_s > 0.0 && limit_horizon_s <= 10.0)) {
    *why = "limit horizon must be in (0, 10] s";
    return false;
  }
  if (!(target_motion_filter >= 0.0 && target_motion_filter <= 1.0)) {
    *why = "target motion filter must be in [0, 1]";
    return false;
  }
  if (!(target_motion_max_interval_s > 0.0 && target_motion_max_interval_s <= 10.0)) {
    *why = "target motion interval must be in (0, 10] s";
    return false;
  }
  return true;
}

Eigen::Vector2d SaturateJointRates(const Eigen::Vector2d& rates, double max_pan_rate,
                                   double max_tilt_rate, bool* saturated) {
  const double ratio = std::max(std::abs(rates.x()) / max_pan_rate,  //
                                std::abs(rates.y()) / max_tilt_rate);
  *saturated = ratio > 1.0;
  return *saturated ? Eigen::Vector2d(rates / ratio) : rates;
}

Eigen::Vector2d KeepWithinJointLimits(const Eigen::Vector2d& rates, double pan, double tilt,
                                      const HeadLimits& limits, double horizon_s, bool* limited) {
  auto cap = [horizon_s](double rate, double position, double lo, double hi) {
    if (rate > 0.0) return std::min(rate, std::max(0.0, (hi - position) / horizon_s));
    if (rate < 0.0) return std::max(rate, std::min(0.0, (lo - position) / horizon_s));
    return rate;
  };
  const Eigen::Vector2d out(cap(rates.x(), pan, limits.pan_min, limits.pan_max),
                            cap(rates.y(), tilt, limits.tilt_min, limits.tilt_max));
  *limited = out != rates;
  return out;
}

Eigen::Vector2d PixelError(const CameraIntrinsics& camera, const Eigen::Vector3d& target_cam,
                           const Eigen::Vector2d& desired_px) {
  return camera.Project(target_cam) - desired_px;
}

struct HeadServo::Impl {
  vpServo task;
  vpFeaturePoint current, desired;
  vpAdaptiveGain gain;
  bool holding = false;
  // Target-motion estimate (normalised image units per second) and the last iteration's data.
  bool have_previous = false;
  double previous_t = 0.0;
  vpColVector previous_error;
  Eigen::Vector2d previous_joints = Eigen::Vector2d::Zero();
  bool have_motion = false;
  vpColVector motion;
};

HeadServo::HeadServo(const HeadServoOptions& options) : options_(options) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("servo options: " + why);
  impl_ = std::make_unique<Impl>();
  impl_->gain.initStandard(options_.gain_at_zero, options_.gain_at_infinity,
                           options_.gain_slope_at_zero);
  impl_->task.setServo(vpServo::EYEINHAND_L_cVe_eJe);
  impl_->task.setInteractionMatrixType(vpServo::CURRENT, vpServo::PSEUDO_INVERSE);
  impl_->task.setLambda(impl_->gain);
  impl_->current.buildFrom(0.0, 0.0, 1.0);
  impl_->desired.buildFrom(0.0, 0.0, 1.0);
  impl_->task.addFeature(impl_->current, impl_->desired);
}

HeadServo::~HeadServo() = default;

void HeadServo::Reset() {
  impl_->holding = false;
  impl_->have_previous = false;
  impl_->have_motion = false;
}

ServoStep HeadServo::Compute(double t, const Eigen::Vector3d& target_cam,
                             const Eigen::Vector2d& desired_px, const CameraIntrinsics& camera,
                             const HeadJoints& head) {
  const double pan = head.pan, tilt = head.tilt;
  const HeadLimits& limits = head.limits;
  ServoStep step;
  Impl& m = *impl_;
  if (!(target_cam.z() > 1e-6) || !target_cam.allFinite()) {
    step.reason = "target behind the camera";
    Reset();
    return step;
  }
  const Eigen::Vector2d error = PixelError(camera, target_cam, desired_px);
  step.error_u_px = error.x();
  step.error_v_px = error.y();
  step.error_px = error.norm();
  const Eigen::Vector3d desired_ray = camera.Ray(desired_px);
  m.current.buildFrom(target_cam.x() / target_cam.z(), target_cam.y() / target_cam.z(),
                      target_cam.z());
  m.desired.buildFrom(desired_ray.x(), desired_ray.y(), target_cam.z());

  const HeadServoMatrices matrices = ServoMatricesOf(options_.geometry, tilt);
  vpColVector law;
  vpMatrix jacobian, inverse;
  vpColVector feature_error;
  try {
    m.task.set_cVe(matrices.cVe);
    m.task.set_eJe(matrices.eJe);
    law = m.task.computeControlLaw();
    jacobian = m.task.getTaskJacobian();
    inverse = m.task.getTaskJacobianPseudoInverse();
    feature_error = m.task.getError();
  } catch (const vpException& e) {
    step.reason = std::string("ViSP servo: ") + e.getMessage();
    Reset();
    return step;
  }
  if (law.size() != 2 || !std::isfinite(law[0]) || !std::isfinite(law[1])) {
    step.reason = "the servo law is not finite (singular head Jacobian)";
    Reset();
    return step;
  }
  step.gain = m.gain(inverse * feature_error);

  // Target motion: the change of the error that the measured joint motion does not explain.
  const Eigen::Vector2d joints(pan, tilt);
  const double dt = t - m.previous_t;
  if (options_.target_motion_filter > 0.0 && m.have_previous && dt > 0.0 &&
      dt <= options_.target_motion_max_interval_s) {
    vpColVector dq(2);
    dq[0] = joints.x() - m.previous_joints.x();
    dq[1] = joints.y() - m.previous_joints.y();
    const vpColVector raw = (feature_error - m.previous_error - jacobian * dq) * (1.0 / dt);
    const double a = options_.target_motion_filter;
    m.motion = m.have_motion ? m.motion * (1.0 - a) + raw * a : raw * a;
    m.have_motion = true;
  } else {
    m.have_motion = false;
  }
  m.have_previous = true;
  m.previous_t = t;
  m.previous_error = feature_error;
  m.previous_joints = joints;

  if (m.have_motion) {
    step.target_speed_px_s = std::hypot(camera.px * m.motion[0], camera.py * m.motion[1]);
  }
  // Hold at convergence, with hysteresis, while the target itself is still.
  const bool target_still = step.target_speed_px_s <= options_.hold_max_target_speed_px_s;
  if (target_still &&
      (m.holding ? step.error_px <= options_.resume_px : step.error_px < options_.convergence_px)) {
    m.holding = true;
    step.converged = true;
    step.ok = true;
    return step;
  }
  m.holding = false;
  Eigen::Vector2d rates(law[0], law[1]);
  if (m.have_motion) {
    const vpColVector feed_forward = inverse * m.motion * -1.0;
    rates += Eigen::Vector2d(feed_forward[0], feed_forward[1]);
    step.compensated = true;
  }
  rates =
      SaturateJointRates(rates, std::min(options_.max_pan_rate, limits.max_pan_speed),
                         std::min(options_.max_tilt_rate, limits.max_tilt_speed), &step.saturated);
  rates = KeepWithinJointLimits(rates, pan, tilt, limits, options_.limit_horizon_s, &step.limited);
  step.pan_rate = rates.x();
  step.tilt_rate = rates.y();
  step.ok = true;
  return step;
}

}  // namespace linetrack

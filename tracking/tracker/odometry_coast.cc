#include "tracking/tracker/odometry_coast.h"

#include <algorithm>
#include <cmath>

#include "models/geometry.h"
#include "models/text_format.h"
#include "tracking/integrity/edge_residual.h"

namespace linetrack {

namespace {

// The sigmas a PoseUncertainty reports from its world covariance.
void SetSigmas(PoseUncertainty* u) {
  const Eigen::Matrix<double, 6, 1> variances = u->world_covariance.diagonal().cwiseMax(0.0);
  u->sigma_x_m = std::sqrt(variances[0]);
  u->sigma_y_m = std::sqrt(variances[1]);
  u->sigma_heading_rad = std::sqrt(variances[5]);
}

bool Finite(const PoseUncertainty& u) {
  return std::isfinite(u.protection_position_m) && std::isfinite(u.protection_rotation_rad) &&
         u.has_covariance();
}

}  // namespace

bool OdometryBound::Check(std::string* why) const {
  if (!(distance_share >= 0.0 && distance_share < 1.0) || !(heading_per_m >= 0.0) ||
      !(turn_share >= 0.0 && turn_share < 1.0)) {
    *why = "odometry bound: distance share in [0, 1), heading per metre >= 0, turn share in [0, 1)";
    return false;
  }
  return true;
}

bool CoastOptions::Check(std::string* why) const {
  if (!bound.Check(why)) return false;
  if (!(max_distance_m >= 0.0) || max_frames < 0) {
    *why = "coasting limits: distance and frames must be >= 0";
    return false;
  }
  return true;
}

CoastLevels GrowCoastLevels(const CoastLevels& levels, double step_m, double turn_rad,
                            const OdometryBound& bound) {
  const double s = bound.distance_share;
  const double lever = 2.0 * std::sin(0.5 * std::min(levels.rotation_rad, kPi));
  CoastLevels out;
  out.position_m = levels.position_m + s * step_m + lever * (1.0 + s) * step_m;
  out.rotation_rad =
      levels.rotation_rad + bound.heading_per_m * step_m + bound.turn_share * std::abs(turn_rad);
  return out;
}

Eigen::Matrix<double, 6, 6> CarryCovariance(const Eigen::Matrix<double, 6, 6>& covariance,
                                            const Eigen::Vector3d& displacement,
                                            const CoastLevels& before, const CoastLevels& after) {
  // dC' = dC + omega x d = dC - [d]x omega; omega' = omega.
  Eigen::Matrix<double, 6, 6> j = Eigen::Matrix<double, 6, 6>::Identity();
  j.topRightCorner<3, 3>() = -CrossProductMatrix(displacement);
  Eigen::Matrix<double, 6, 6> out = j * covariance * j.transpose();
  const double position =
      (after.position_m * after.position_m - before.position_m * before.position_m) / 9.0;
  const double heading =
      (after.rotation_rad * after.rotation_rad - before.rotation_rad * before.rotation_rad) / 9.0;
  out(0, 0) += std::max(position, 0.0);
  out(1, 1) += std::max(position, 0.0);
  out(5, 5) += std::max(heading, 0.0);
  return out;
}

Eigen::Isometry3d PredictFromOdometry(const Eigen::Isometry3d& last, const RobotPose& then,
                                      const RobotPose& now) {
  return CamFromWorld(now) * CamFromWorld(then).inverse() * last;
}

CoastAnchor AnchorAtFix(const Eigen::Isometry3d& pose, const PoseUncertainty& uncertainty,
                        const RobotPose& odometry, long frame) {
  CoastAnchor a;
  a.cam_from_world = pose;
  a.uncertainty = uncertainty;
  a.odometry = odometry;
  a.fix_frame = frame;
  return a;
}

CoastedPose Coast(const CoastAnchor& anchor, const RobotPose& now, const CoastOptions& options,
                  const IntegrityOptions& alert) {
  CoastedPose out;
  out.cam_from_world = PredictFromOdometry(anchor.cam_from_world, anchor.odometry, now);
  const double step = std::hypot(now.x - anchor.odometry.x, now.y - anchor.odometry.y);
  const double turn = WrapAngle(now.heading - anchor.odometry.heading);
  const PoseUncertainty& before = anchor.uncertainty;
  const CoastLevels grown = GrowCoastLevels(
      {before.protection_position_m, before.protection_rotation_rad}, step, turn, options.bound);

  CoastAnchor& next = out.anchor;
  next = anchor;
  next.cam_from_world = out.cam_from_world;
  next.odometry = now;
  next.driven_m += step;
  next.frames += 1;
  // The odometry's own accumulated error bound, without the lever of the anchor's heading error.
  const OdometryBound& b = options.bound;
  next.noise.position_m = anchor.noise.position_m + b.distance_share * step;
  next.noise.rotation_rad =
      anchor.noise.rotation_rad + b.heading_per_m * step + b.turn_share * std::abs(turn);

  PoseUncertainty& u = next.uncertainty;
  u = PoseUncertainty();
  out.note =
      "odometry: " + Fixed(next.driven_m, 2) + " m since frame " + std::to_string(anchor.fix_frame);
  if (!Finite(before)) {
    u.reason = "no bound to coast from";
    out.uncertainty = u;
    return out;
  }
  if (next.driven_m > options.max_distance_m || next.frames > options.max_frames) {
    u.reason = out.note + ", beyond the coasting limit (" + Fixed(options.max_distance_m, 2) +
               " m, " + std::to_string(options.max_frames) + " frames)";
    out.uncertainty = u;
    return out;
  }
  const Eigen::Vector3d displacement =
      out.cam_from_world.inverse().translation() - anchor.cam_from_world.inverse().translation();
  u.world_covariance =
      CarryCovariance(before.world_covariance, displacement, anchor.noise, next.noise);
  SetSigmas(&u);
  u.protection_position_m = grown.position_m;
  u.protection_rotation_rad = grown.rotation_rad;
  const bool within =
      grown.position_m <= alert.alert_position_m && grown.rotation_rad <= alert.alert_rotation_rad;
  u.status = within ? IntegrityStatus::kTracking : IntegrityStatus::kDegraded;
  u.reason = within ? "" : out.note + ", protection levels beyond the alert limits";
  out.uncertainty = u;
  return out;
}

PoseDisagreement Disagreement(const Eigen::Isometry3d& a, const PoseUncertainty& ua,
                              const Eigen::Isometry3d& b, const PoseUncertainty& ub) {
  const WorldTwist d = WorldTwistBetween(a, b);
  PoseDisagreement out;
  out.position_m = d.head<2>().norm();
  out.rotation_rad = std::abs(d[5]);
  out.contradicts = out.position_m > ua.protection_position_m + ub.protection_position_m ||
                    out.rotation_rad > ua.protection_rotation_rad + ub.protection_rotation_rad;
  return out;
}

PoseUncertainty UnionOfContradicting(const PoseUncertainty& reported, const PoseUncertainty& other,
                                     const PoseDisagreement& disagreement, const std::string& why) {
  PoseUncertainty u = reported;
  u.protection_position_m = std::max(reported.protection_position_m,
                                     disagreement.position_m + other.protection_position_m);
  u.protection_rotation_rad = std::max(reported.protection_rotation_rad,
                                       disagreement.rotation_rad + other.protection_rotation_rad);
  if (u.has_covariance()) {
    const double p2 = disagreement.position_m * disagreement.position_m;
    u.world_covariance(0, 0) += p2;
    u.world_covariance(1, 1) += p2;
    u.world_covariance(5, 5) += disagreement.rotation_rad * disagreement.rotation_rad;
    SetSigmas(&u);
  }
  u.status = IntegrityStatus::kDegraded;
  u.reason = reported.reason.empty() ? why : why + "; " + reported.reason;
  return u;
}

bool PreferCoasted(const PoseUncertainty& image, const PoseUncertainty& coasted) {
  return coasted.status == IntegrityStatus::kTracking && image.status != IntegrityStatus::kTracking;
}

}  // namespace linetrack

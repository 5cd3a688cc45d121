#include "matching/observed_line.h"

#include <cmath>

#include "models/errors.h"
#include "models/robot_pose.h"

namespace linetrack {

bool LineNoise::Check(std::string* why) const {
  const double values[] = {offset_px, angle_deg, focal_relative, tilt_deg, fragment_offset_px};
  for (double v : values) {
    if (!std::isfinite(v) || v < 0.0) {
      *why = "line noise values must be finite and >= 0";
      return false;
    }
  }
  if (!(vertical_clutter_fraction >= 0.0 && vertical_clutter_fraction < 1.0) ||
      !(detection_probability > 0.0 && detection_probability < 1.0) ||
      !(clutter_share > 0.0 && clutter_share <= 1.0)) {
    *why =
        "line noise: vertical_clutter_fraction in [0, 1), detection_probability in (0, 1), "
        "clutter_share in (0, 1]";
    return false;
  }
  if (offset_px + angle_deg == 0.0) {
    *why = "line noise: offset_px or angle_deg must be positive";
    return false;
  }
  return true;
}

namespace {

// Jacobian columns of the unit normal n = (r1 x r2)/|r1 x r2| for perturbations of the rays.
Eigen::Vector3d NormalDerivative(const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                                 const Eigen::Vector3d& dr1, const Eigen::Vector3d& dr2) {
  const Eigen::Vector3d nu = r1.cross(r2);
  const double norm = nu.norm();
  const Eigen::Vector3d n = nu / norm;
  const Eigen::Vector3d dnu = dr1.cross(r2) + r1.cross(dr2);
  return (dnu - n * n.dot(dnu)) / norm;
}

}  // namespace

std::vector<ObservedLine> PrepareLines(const std::vector<Segment2>& lines,
                                       const CameraIntrinsics& camera, double tilt,
                                       const LineNoise& noise, double gate_sigmas) {
  const Eigen::Matrix3d level = LevelFromCam(tilt);
  // d(level)/d(tilt), for the tilt-reading noise.
  const double ct = std::cos(tilt), st = std::sin(tilt);
  Eigen::Matrix3d dlevel;
  dlevel << 0, 0, 0, 0, -st, ct, 0, -ct, -st;
  const double sigma_angle = DegToRad(noise.angle_deg);
  const double sigma_tilt = DegToRad(noise.tilt_deg);

  std::vector<ObservedLine> out;
  out.reserve(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    const Segment2& s = lines[i];
    if (!s.a.allFinite() || !s.b.allFinite()) {
      throw InputError("line " + std::to_string(i) + ": coordinates are not finite");
    }
    const double length = s.Length();
    if (length < 1e-6) throw InputError("line " + std::to_string(i) + ": zero-length segment");

    ObservedLine line;
    line.index = static_cast<int>(i);
    line.pixels = s;
    line.length_px = length;
    const Eigen::Vector3d r1 = camera.Ray(s.a), r2 = camera.Ray(s.b);
    const Eigen::Vector3d nu = r1.cross(r2);
    const Eigen::Vector3d n = nu.normalized();

    // Perpendicular endpoint displacements e1, e2 (pixels) along the image normal m:
    // e = offset +- (L/2) angle, so Var(e_k) = so^2 + (L/2)^2 sa^2, Cov = so^2 - (L/2)^2 sa^2.
    const Eigen::Vector2d dir = (s.b - s.a) / length;
    const Eigen::Vector3d mu(-dir.y() / camera.px, dir.x() / camera.py, 0.0);
    const Eigen::Vector3d j1 = NormalDerivative(r1, r2, mu, Eigen::Vector3d::Zero());
    const Eigen::Vector3d j2 = NormalDerivative(r1, r2, Eigen::Vector3d::Zero(), mu);
    const double so2 = noise.offset_px * noise.offset_px;
    const double sa2 = 0.25 * length * length * sigma_angle * sigma_angle;
    Eigen::Matrix3d cov = (so2 + sa2) * (j1 * j1.transpose() + j2 * j2.transpose()) +
                          (so2 - sa2) * (j1 * j2.transpose() + j2 * j1.transpose());
    // Relative focal error: the normalised coordinates scale by (1 + eps).
    const Eigen::Vector3d js = NormalDerivative(r1, r2, Eigen::Vector3d(r1.x(), r1.y(), 0.0),
                                                Eigen::Vector3d(r2.x(), r2.y(), 0.0));
    cov += noise.focal_relative * noise.focal_relative * js * js.transpose();

    line.normal = level * n;
    line.normal_cov = level * cov * level.transpose();
    const Eigen::Vector3d jt = dlevel * n;
    line.normal_cov += sigma_tilt * sigma_tilt * jt * jt.transpose();
    line.ray_a = (level * r1).normalized();
    line.ray_b = (level * r2).normalized();

    // Vertical candidates: a vertical world line has nL_y = 0.
    const double ny = line.normal.y();
    const double sigma_ny = std::sqrt(std::max(line.normal_cov(1, 1), 1e-18));
    line.maybe_vertical = std::abs(ny) <= gate_sigmas * sigma_ny;
    const double f = noise.vertical_clutter_fraction, z = ny / sigma_ny;
    line.clutter_log_density =
        std::log((1.0 - f) + f * kPi / (std::sqrt(2.0 * kPi) * std::max(sigma_angle, 1e-6)) *
                                 std::exp(-0.5 * z * z)) +
        std::log(std::max(noise.clutter_share * static_cast<double>(lines.size()), 1.0) /
                 noise.detection_probability);
    const double nx = line.normal.x(), nz = line.normal.z();
    const double horizontal2 = nx * nx + nz * nz;
    Eigen::Vector2d bearing_dir(nz, -nx);  // (x, z) of the plane's horizontal direction
    const Eigen::Vector3d mid = line.ray_a + line.ray_b;
    if (bearing_dir.dot(Eigen::Vector2d(mid.x(), mid.z())) < 0.0) bearing_dir = -bearing_dir;
    line.bearing = std::atan2(bearing_dir.x(), bearing_dir.y());
    const Eigen::Vector3d grad(nz / horizontal2, 0.0, -nx / horizontal2);
    line.bearing_sigma = std::sqrt(std::max(FormVariance(line, grad), 0.0));
    out.push_back(line);
  }
  return out;
}

}  // namespace linetrack

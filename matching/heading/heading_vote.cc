#include "matching/heading/heading_vote.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "matching/heading/vanishing_geometry.h"
#include "models/errors.h"
#include "models/robot_pose.h"

namespace linetrack {
namespace {

Segment2 Turned(const Segment2& s, double angle) {
  const Eigen::Vector2d mid = s.Mid();
  const double c = std::cos(angle), si = std::sin(angle);
  auto turn = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d d = p - mid;
    return Eigen::Vector2d(mid.x() + c * d.x() - si * d.y(), mid.y() + si * d.x() + c * d.y());
  };
  return {turn(s.a), turn(s.b)};
}

Segment2 Shifted(const Segment2& s, double offset) {
  const Eigen::Vector2d d = (s.b - s.a).normalized();
  const Eigen::Vector2d normal(-d.y(), d.x());
  return {s.a + offset * normal, s.b + offset * normal};
}

// Adds InlierLogRatio of a vote centred at `centre` (standard deviation sigma, extent `gate`) to
// the bins whose centres lie in [cell_lo, cell_hi) (radians, unwrapped around `centre`).
void AddKernel(double centre, double sigma, double gate, Eigen::Vector2d cell, double outlier,
               HeadingAccumulator* acc) {
  const int n = static_cast<int>(acc->scores.size());
  const double lo = std::max(centre - gate, cell.x()), hi = std::min(centre + gate, cell.y());
  const int first = static_cast<int>(std::ceil(lo / acc->bin_width - 0.5));
  const int last = static_cast<int>(std::floor(hi / acc->bin_width - 0.5));
  for (int b = first; b <= last && b - first < n; ++b) {
    const double z = ((b + 0.5) * acc->bin_width - centre) / sigma;
    acc->scores[((b % n) + n) % n] += InlierLogRatio(z, sigma, kPi, outlier);
  }
}

}  // namespace

double InlierLogRatio(double z, double sigma, double period, double outlier_probability) {
  const double c =
      (1.0 - outlier_probability) / outlier_probability * period / (std::sqrt(2.0 * kPi) * sigma);
  return std::log1p(c * std::exp(-0.5 * z * z));
}

double InlierPosterior(double z, double sigma, double period, double outlier_probability) {
  const double c =
      (1.0 - outlier_probability) / outlier_probability * period / (std::sqrt(2.0 * kPi) * sigma);
  const double in = c * std::exp(-0.5 * z * z);
  return in / (1.0 + in);
}

std::vector<VoteLine> PrepareVoteLines(const std::vector<Segment2>& lines,
                                       const CameraIntrinsics& camera,
                                       const HeadingOptions& options) {
  std::vector<VoteLine> out;
  const double min_gate = DegToRad(options.min_gate_deg);
  for (size_t i = 0; i < lines.size(); ++i) {
    const Segment2& s = lines[i];
    if (!s.a.allFinite() || !s.b.allFinite()) {
      throw InputError("line " + std::to_string(i) + ": endpoints are not finite");
    }
    const double length = s.Length();
    if (length < options.min_length_px || length == 0.0) continue;
    VoteLine v;
    v.index = static_cast<int>(i);
    v.segment = s;
    v.normal = InterpretationNormal(camera, s);
    v.angle_sigma = std::hypot(std::sqrt(2.0) * options.endpoint_sigma_px / length,
                               DegToRad(options.line_angle_sigma_deg));
    const double shift =
        std::hypot(options.endpoint_sigma_px / std::sqrt(2.0), options.line_offset_sigma_px);
    for (int k = 0; k < 2; ++k) {
      const double sign = k == 0 ? -1.0 : 1.0;
      v.turned[k] = InterpretationNormal(camera, Turned(s, sign * v.angle_sigma));
      v.shifted[k] = InterpretationNormal(camera, Shifted(s, sign * shift));
    }
    v.gate = std::max(options.gate_sigmas * v.angle_sigma, min_gate);
    out.push_back(v);
  }
  return out;
}

std::vector<bool> VerticalInliers(const std::vector<VoteLine>& lines,
                                  const CameraIntrinsics& camera, double tilt) {
  const Eigen::Vector3d down = DownInCamera(tilt);
  std::vector<bool> out(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    out[i] = std::abs(VanishingResidual(camera, lines[i].segment, down)) <= lines[i].gate;
  }
  return out;
}

Bearing BearingAt(const VoteLine& line, double tilt) {
  const Eigen::Matrix3d level = LevelFromCam(tilt);
  Bearing b;
  b.alpha = HorizontalBearing(level * line.normal);
  double turn = 0.0, shift = 0.0;
  for (int k = 0; k < 2; ++k) {
    turn = std::max(
        turn, std::abs(WrapCentred(HorizontalBearing(level * line.turned[k]) - b.alpha, kPi)));
    shift = std::max(
        shift, std::abs(WrapCentred(HorizontalBearing(level * line.shifted[k]) - b.alpha, kPi)));
  }
  b.sigma = std::hypot(turn, shift);
  return b;
}

double HeadingAccumulator::Max() const {
  return scores.empty() ? 0.0 : *std::max_element(scores.begin(), scores.end());
}

double HeadingAccumulator::Peak() const {
  const auto best = std::max_element(scores.begin(), scores.end());
  return (static_cast<double>(best - scores.begin()) + 0.5) * bin_width;
}

void HeadingAccumulator::Suppress(double heading, double half_width) {
  const int n = static_cast<int>(scores.size());
  const int first = static_cast<int>(std::floor((heading - half_width) / bin_width));
  const int last = static_cast<int>(std::floor((heading + half_width) / bin_width));
  for (int b = first; b <= last && b - first < n; ++b)
    scores[((b % n) + n) % n] = 0.0;
}

HeadingAccumulator VoteHeadings(const std::vector<VoteLine>& lines,
                                const std::vector<bool>& vertical, double tilt,
                                const ModelDirections& directions, const HeadingOptions& options) {
  HeadingAccumulator acc;
  const int n = std::max(1, static_cast<int>(std::lround(180.0 / options.bin_deg)));
  acc.bin_width = kPi / n;
  acc.scores.assign(n, 0.0);
  const double max_sigma = DegToRad(options.max_bearing_sigma_deg);
  const double min_sigma = DegToRad(options.min_bearing_sigma_deg);
  const std::vector<double>& theta = directions.angles;  // ascending in [0, pi)
  const size_t k_count = theta.size();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (vertical[i]) continue;
    const Bearing b = BearingAt(lines[i], tilt);
    if (b.sigma > max_sigma) continue;
    const double sigma = std::max(b.sigma, min_sigma);
    // Each direction votes only in its own cell (half-way to its neighbours), so that a segment
    // counts once per bin: the nearest direction's kernel.
    for (size_t k = 0; k < k_count; ++k) {
      const double prev = k == 0 ? theta[k_count - 1] - kPi : theta[k - 1];
      const double next = k + 1 == k_count ? theta[0] + kPi : theta[k + 1];
      const double centre = theta[k] + b.alpha;
      const double half_lo = k_count == 1 ? 0.5 * kPi : 0.5 * (theta[k] - prev);
      const double half_hi = k_count == 1 ? 0.5 * kPi : 0.5 * (next - theta[k]);
      AddKernel(centre, sigma, options.gate_sigmas * sigma, {centre - half_lo, centre + half_hi},
                options.outlier_probability, &acc);
    }
  }
  return acc;
}

double VerticalScore(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                     double tilt, double outlier_probability, std::vector<bool>* vertical) {
  const Eigen::Vector3d down = DownInCamera(tilt);
  double score = 0.0;
  if (vertical) vertical->assign(lines.size(), false);
  for (size_t i = 0; i < lines.size(); ++i) {
    const double r = VanishingResidual(camera, lines[i].segment, down);
    if (std::abs(r) > lines[i].gate) continue;
    score +=
        InlierLogRatio(r / lines[i].angle_sigma, lines[i].angle_sigma, kPi, outlier_probability);
    if (vertical) (*vertical)[i] = true;
  }
  return score;
}

TiltScan ScanTilt(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                  const ModelDirections& directions, const HeadingOptions& options) {
  const int steps = static_cast<int>(
      std::floor((options.tilt_max_deg - options.tilt_min_deg) / options.tilt_step_deg + 1e-9));
  TiltScan best;
  best.score = -1.0;
  for (int s = 0; s <= steps; ++s) {
    const double tilt = DegToRad(options.tilt_min_deg + s * options.tilt_step_deg);
    std::vector<bool> vertical;
    const double score =
        VerticalScore(lines, camera, tilt, options.outlier_probability, &vertical) +
        VoteHeadings(lines, vertical, tilt, directions, options).Max();
    if (score > best.score) best = {tilt, score};
  }
  return best;
}

Eigen::Vector3d AssignedDirection(int a, const ModelDirections& directions) {
  if (a == 0) return {0.0, 0.0, -1.0};
  const double theta = directions.angles[a - 1];
  return {std::cos(theta), std::sin(theta), 0.0};
}

std::vector<int> AssignLines(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                             double heading, double tilt, const ModelDirections& directions,
                             const HeadingOptions& options) {
  const Eigen::Matrix3d rotation = CamFromWorldRotation(heading, tilt);
  const std::vector<bool> vertical = VerticalInliers(lines, camera, tilt);
  const double max_sigma = DegToRad(options.max_bearing_sigma_deg);
  std::vector<int> out(lines.size(), -1);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (vertical[i]) {
      out[i] = 0;
      continue;
    }
    if (BearingAt(lines[i], tilt).sigma > max_sigma) continue;
    double best = lines[i].gate;
    for (size_t k = 0; k < directions.angles.size(); ++k) {
      const Eigen::Vector3d d = rotation * AssignedDirection(static_cast<int>(k) + 1, directions);
      const double r = std::abs(VanishingResidual(camera, lines[i].segment, d));
      if (r <= best) {
        best = r;
        out[i] = static_cast<int>(k) + 1;
      }
    }
  }
  return out;
}

namespace {

// Residuals r_i = VanishingResidual_i / angle_sigma_i of the assigned lines at (heading, tilt).
Eigen::VectorXd Residuals(const RefinementContext& context, const std::vector<int>& assignment,
                          const Eigen::Vector2d& rotation_parameters) {
  const Eigen::Matrix3d rotation =
      CamFromWorldRotation(rotation_parameters.x(), rotation_parameters.y());
  const std::vector<VoteLine>& lines = *context.lines;
  std::vector<double> r;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (assignment[i] < 0) continue;
    const Eigen::Vector3d d = rotation * AssignedDirection(assignment[i], *context.directions);
    r.push_back(VanishingResidual(*context.camera, lines[i].segment, d) / lines[i].angle_sigma);
  }
  return Eigen::Map<Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
}

// Inlier posteriors of the residuals (the lines' angles, outliers uniform over pi).
Eigen::VectorXd Posteriors(const RefinementContext& context, const std::vector<int>& assignment,
                           const Eigen::VectorXd& r) {
  Eigen::VectorXd w(r.size());
  int j = 0;
  for (size_t i = 0; i < assignment.size(); ++i) {
    if (assignment[i] < 0) continue;
    w[j] = InlierPosterior(r[j], (*context.lines)[i].angle_sigma, kPi, context.outlier_probability);
    ++j;
  }
  return w;
}

Eigen::MatrixXd NumericalJacobian(const RefinementContext& context,
                                  const std::vector<int>& assignment, const Eigen::Vector2d& p,
                                  int dof) {
  constexpr double kStep = 1e-7;  // radians, central differences
  Eigen::MatrixXd jacobian;
  for (int c = 0; c < dof; ++c) {
    Eigen::Vector2d plus = p, minus = p;
    plus[c] += kStep;
    minus[c] -= kStep;
    const Eigen::VectorXd column =
        (Residuals(context, assignment, plus) - Residuals(context, assignment, minus)) /
        (2.0 * kStep);
    if (jacobian.size() == 0) jacobian.resize(column.size(), dof);
    jacobian.col(c) = column;
  }
  return jacobian;
}

}  // namespace

RotationFit RefineRotation(const RefinementContext& context, const std::vector<int>& assignment,
                           const RotationStart& start) {
  const int dof = start.estimate_tilt ? 2 : 1;
  Eigen::Vector2d p(start.heading, start.tilt);
  Eigen::VectorXd r = Residuals(context, assignment, p);
  Eigen::VectorXd w = Posteriors(context, assignment, r);
  auto cost = [&](const Eigen::VectorXd& res) { return (w.array() * res.array().square()).sum(); };
  for (int it = 0; it < context.iterations && r.size() >= dof; ++it) {
    const Eigen::MatrixXd jacobian = NumericalJacobian(context, assignment, p, dof);
    const Eigen::MatrixXd normal = jacobian.transpose() * w.asDiagonal() * jacobian;
    const Eigen::VectorXd step =
        normal.ldlt().solve(-jacobian.transpose() * (w.array() * r.array()).matrix());
    if (!step.allFinite()) break;
    double scale = 1.0;
    Eigen::Vector2d next = p;
    Eigen::VectorXd r_next;
    for (; scale > 1e-3; scale *= 0.5) {
      next = p;
      next.head(dof) += scale * step;
      r_next = Residuals(context, assignment, next);
      if (cost(r_next) <= cost(r)) break;
    }
    if (cost(r_next) > cost(r)) break;
    p = next;
    r = r_next;
    w = Posteriors(context, assignment, r);
    if (step.norm() * scale < 1e-10) break;
  }
  RotationFit fit;
  fit.heading = p.x();
  fit.tilt = p.y();
  fit.residuals = static_cast<int>(r.size());
  if (r.size() == 0) return fit;
  fit.inliers = w.sum();
  fit.rms_sigmas = std::sqrt(cost(r) / std::max(1e-9, fit.inliers));
  const Eigen::MatrixXd jacobian = NumericalJacobian(context, assignment, p, dof);
  const Eigen::MatrixXd normal = jacobian.transpose() * w.asDiagonal() * jacobian;
  if (normal.determinant() > 0.0) {
    const double chi2 = fit.inliers > dof ? cost(r) / (fit.inliers - dof) : 1.0;
    const Eigen::MatrixXd covariance = normal.inverse() * std::max(1.0, chi2);
    fit.heading_sigma = std::sqrt(covariance(0, 0));
    if (dof == 2) fit.tilt_sigma = std::sqrt(covariance(1, 1));
  }
  return fit;
}

}  // namespace linetrack

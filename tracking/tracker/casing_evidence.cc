#include "tracking/tracker/casing_evidence.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tracking/tracker/image_sampling.h"

namespace linetrack {

namespace {

constexpr double kStepPx = 0.5;            // between samples of a profile
constexpr double kShiftM = 0.01;           // the edge's test shift across itself (metres)
constexpr double kCasingNearClipM = 0.05;  // metres

// The image line through the projections of a and b: a point and the unit normal (-d_y, d_x).
struct ImageLine {
  Eigen::Vector2d origin, normal;
};

bool Project(const CameraIntrinsics& camera, const Eigen::Isometry3d& pose,
             const Eigen::Vector3d& a, const Eigen::Vector3d& b, ImageLine* line) {
  const Eigen::Vector3d ca = pose * a, cb = pose * b;
  if (ca.z() <= kCasingNearClipM || cb.z() <= kCasingNearClipM) return false;
  const Eigen::Vector2d pa = camera.Project(ca), pb = camera.Project(cb);
  const Eigen::Vector2d d = pb - pa;
  if (!(d.norm() > 1e-9)) return false;
  line->origin = pa;
  line->normal = Eigen::Vector2d(-d.y(), d.x()).normalized();
  return true;
}

// |gradient| along `normal` at offsets -reach..reach (kStepPx apart) from p, averaged over three
// parallel lines one pixel apart; false when any sample falls outside the image.
bool GradientProfile(const vpImage<unsigned char>& image, const Eigen::Vector2d& p,
                     const Eigen::Vector2d& normal, double reach, std::vector<double>* out) {
  const Eigen::Vector2d along(normal.y(), -normal.x());
  const int half = static_cast<int>(std::ceil(reach / kStepPx)) + 1;
  std::vector<double> intensity(2 * half + 1, 0.0);
  for (int j = -half; j <= half; ++j) {
    for (int l = -1; l <= 1; ++l) {
      double value = 0.0;
      if (!SampleBilinear(image, p + j * kStepPx * normal + l * along, &value)) return false;
      intensity[j + half] += value / 3.0;
    }
  }
  out->assign(2 * half + 1, 0.0);
  for (int j = 1; j < 2 * half; ++j)
    (*out)[j] = std::abs(intensity[j + 1] - intensity[j - 1]) / (2.0 * kStepPx);
  return true;
}

// One point's profile: its own step (the peak within 1.5 px), that peak's half-maximum width and
// the offset (pixels along the normal) of the strongest other ridge between `nearest` and
// `reach` on either side, NaN when none is strong enough.
struct PointProfile {
  double step = 0.0, half_width_px = 0.0;
  double ridge_px = std::nan("");
};

PointProfile ReadProfile(const std::vector<double>& g, double nearest, double reach,
                         const CasingEvidenceOptions& options) {
  PointProfile out;
  const int centre = static_cast<int>(g.size()) / 2;
  const int own = static_cast<int>(std::lround(1.5 / kStepPx));
  int peak = centre;
  for (int j = centre - own; j <= centre + own; ++j) {
    if (g[j] > g[peak]) peak = j;
  }
  out.step = g[peak];
  int lo = peak, hi = peak;
  while (lo > 1 && g[lo - 1] >= 0.5 * out.step)
    --lo;
  while (hi + 2 < static_cast<int>(g.size()) && g[hi + 1] >= 0.5 * out.step)
    ++hi;
  out.half_width_px = (hi - lo + 1) * kStepPx;
  const double floor = std::max(options.min_gradient, options.relative_strength * out.step);
  double best = floor;
  for (int j = 1; j + 1 < static_cast<int>(g.size()); ++j) {
    const double offset = (j - centre) * kStepPx;
    if (std::abs(offset) < nearest || std::abs(offset) > reach) continue;
    if (g[j] < g[j - 1] || g[j] < g[j + 1] || g[j] < best) continue;
    best = g[j];
    out.ridge_px = offset;
  }
  return out;
}

// The most common width among `widths` (metres) with their tolerances: its count and value.
std::pair<int, double> CommonWidth(const std::vector<double>& widths,
                                   const std::vector<double>& tolerances) {
  std::pair<int, double> best{0, 0.0};
  for (size_t i = 0; i < widths.size(); ++i) {
    int count = 0;
    for (size_t j = 0; j < widths.size(); ++j) {
      if (std::abs(widths[j] - widths[i]) <= tolerances[i]) ++count;
    }
    if (count > best.first) best = {count, widths[i]};
  }
  return best;
}

}  // namespace

bool CasingEvidenceOptions::Check(std::string* why) const {
  if (!(min_width_m > 0.0 && max_width_m > min_width_m && min_separation_px > 0.0 &&
        max_search_px > min_separation_px && relative_strength > 0.0 && min_gradient >= 0.0 &&
        width_tolerance_px > 0.0 && min_points >= 1 && min_examined_share >= 0.0 &&
        min_examined_share <= 1.0 && min_ridge_share > 0.0 && min_ridge_share <= 1.0)) {
    *why =
        "casing evidence: widths 0 < min < max, separations and tolerances > 0, shares in (0, 1]";
    return false;
  }
  return true;
}

CasingEvidence FindCasing(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                          const Eigen::Isometry3d& cam_from_world, const EdgeObservation& edge,
                          const CasingEvidenceOptions& options) {
  CasingEvidence out;
  ImageLine line, shifted;
  const Eigen::Vector3d shift = kShiftM * edge.casing_direction;
  if (edge.casing_direction.isZero() || edge.points.empty() ||
      !Project(camera, cam_from_world, edge.a, edge.b, &line) ||
      !Project(camera, cam_from_world, edge.a + shift, edge.b + shift, &shifted)) {
    return out;
  }
  // The shifted line's normal against the line's: the same for every point.
  const double facing = shifted.normal.dot(line.normal);
  if (!(std::abs(facing) > 0.5)) return out;
  std::vector<double> widths, tolerances, profile;
  for (const Eigen::Vector2d& p : edge.points) {
    // Pixels along the normal per metre of shift: where p + s normal meets the shifted line.
    const double per_m = -shifted.normal.dot(p - shifted.origin) / facing / kShiftM;
    const double nearest =
        std::max(options.min_separation_px, std::abs(per_m) * options.min_width_m);
    const double reach = std::min(options.max_search_px, std::abs(per_m) * options.max_width_m);
    if (!(reach > nearest) || !GradientProfile(image, p, line.normal, reach + 1.0, &profile)) {
      continue;
    }
    const PointProfile read = ReadProfile(profile, nearest, reach, options);
    if (read.step < options.min_gradient || read.half_width_px > nearest) continue;
    ++out.examined;
    if (std::isnan(read.ridge_px)) continue;
    widths.push_back(read.ridge_px / per_m);
    tolerances.push_back(options.width_tolerance_px / std::abs(per_m));
  }
  const std::pair<int, double> common = CommonWidth(widths, tolerances);
  out.with_ridge = common.first;
  out.width_m = common.second;
  const int points = static_cast<int>(edge.points.size());
  if (out.examined < options.min_points || out.examined < options.min_examined_share * points) {
    return out;
  }
  out.verdict = out.with_ridge >= options.min_ridge_share * out.examined ? CasingVerdict::kSeen
                                                                         : CasingVerdict::kAbsent;
  return out;
}

int ClearCasingsNotSeen(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                        const Eigen::Isometry3d& cam_from_world,
                        const CasingEvidenceOptions& options,
                        std::vector<EdgeObservation>* observations) {
  if (!options.enabled) return 0;
  int cleared = 0;
  for (EdgeObservation& o : *observations) {
    if (o.casing_direction.isZero()) continue;
    if (FindCasing(image, camera, cam_from_world, o, options).verdict == CasingVerdict::kAbsent) {
      o.casing_direction.setZero();
      ++cleared;
    }
  }
  return cleared;
}

}  // namespace linetrack

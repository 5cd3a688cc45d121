// The pure pieces of the synthetic scenes' noise model: portable random draws, segment
// perturbation and fragmentation, the paper's camera and prior presets, option checks.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "models/errors.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {

CameraIntrinsics PaperSyntheticCamera() {
  CameraIntrinsics camera;
  camera.name = "synthetic";
  camera.width = 640;
  camera.height = 480;
  camera.px = camera.py = 1000.0;
  camera.u0 = 320.0;
  camera.v0 = 240.0;
  return camera;
}

PriorBounds QualityIndexBounds(int qi) {
  switch (qi) {
    case 1:
      return {0.30, DegToRad(10.0)};
    case 2:
      return {0.50, DegToRad(15.0)};
    case 3:
      return {0.75, DegToRad(20.0)};
    default:
      throw InputError("qi: " + std::to_string(qi) + " is not a prior quality index (1, 2 or 3)");
  }
}

namespace {

// Sets *why and returns false unless lo <= hi, both finite and >= floor.
bool GoodRange(double lo, double hi, double floor, const char* name, std::string* why) {
  if (std::isfinite(lo) && std::isfinite(hi) && lo >= floor && lo <= hi) return true;
  std::ostringstream msg;
  msg << name << ": [" << lo << ", " << hi << "] must be finite, ordered and >= " << floor;
  *why = msg.str();
  return false;
}

bool GoodCount(int lo, int hi, const char* name, std::string* why) {
  if (lo >= 0 && lo <= hi) return true;
  *why = std::string(name) + ": [" + std::to_string(lo) + ", " + std::to_string(hi) +
         "] must be ordered and >= 0";
  return false;
}

}  // namespace

bool SyntheticSceneOptions::Check(std::string* why) const {
  std::string local;
  if (why == nullptr) why = &local;
  if (count <= 0) {
    *why = "count: " + std::to_string(count) + " must be > 0";
    return false;
  }
  if (storey < 0 || !std::isfinite(floor_z)) {
    *why = "storey must be >= 0 and floor_z finite";
    return false;
  }
  if (!camera.Check(why)) return false;
  if (camera.width <= 0 || camera.height <= 0) {
    *why = "camera: the image size must be known";
    return false;
  }
  const double max_tilt = 0.5 * kPi - 1e-3;
  if (!GoodRange(height_min, height_max, 0.0, "height range (m)", why) ||
      !GoodRange(tilt_min, tilt_max, -max_tilt, "tilt range (rad)", why)) {
    return false;
  }
  if (tilt_max > max_tilt) {
    *why = "tilt range: must stay below 90 degrees";
    return false;
  }
  if (!GoodRange(0.0, calibration_sigma, 0.0, "calibration sigma", why) ||
      !GoodRange(0.0, angle_sigma, 0.0, "angle sigma (rad)", why) ||
      !GoodRange(0.0, offset_sigma_px, 0.0, "offset sigma (px)", why) ||
      !GoodRange(0.0, shorten_max, 0.0, "shorten max", why) ||
      !GoodRange(0.0, split_probability, 0.0, "split probability", why) ||
      !GoodRange(0.0, split_gap, 0.0, "split gap", why) ||
      !GoodRange(min_length_px, min_length_px, 1e-6, "min length (px)", why) ||
      !GoodRange(0.0, vertical_clutter_fraction, 0.0, "vertical clutter fraction", why) ||
      !GoodRange(vertical_clutter_distance_min, vertical_clutter_distance_max, 0.1,
                 "vertical clutter distance (m)", why) ||
      !GoodRange(vertical_clutter_height_min, vertical_clutter_height_max, 0.0,
                 "vertical clutter height (m)", why) ||
      !GoodRange(clutter_length_min_px, clutter_length_max_px, 1e-6, "clutter length (px)", why) ||
      !GoodRange(delta_t, delta_t, 0.0, "delta_t (m)", why) ||
      !GoodRange(parallel_offset_min_px, parallel_offset_max_px, 0.0, "parallel offset (px)",
                 why)) {
    return false;
  }
  if (shorten_max >= 0.5 || split_probability > 1.0 || split_gap >= 0.5 ||
      vertical_clutter_fraction > 1.0) {
    *why = "shorten max and split gap must be < 0.5, probabilities and fractions <= 1";
    return false;
  }
  if (!(delta_phi > 0.0 && delta_phi <= kPi)) {
    *why = "delta_phi: must be in (0, 180] degrees";
    return false;
  }
  if (!GoodCount(min_visible_edges, max_visible_edges, "visible edges per scene", why) ||
      !GoodCount(min_clutter, max_clutter, "clutter lines per scene", why) ||
      !GoodCount(parallel_clutter, parallel_clutter, "parallel clutter lines per scene", why)) {
    return false;
  }
  if (max_visible_edges == 0 || max_attempts <= 0) {
    *why = "scenes need at least one visible edge and max_attempts > 0";
    return false;
  }
  return true;
}

SceneRandom::SceneRandom(uint64_t seed, uint64_t stream) {
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32),
                    static_cast<uint32_t>(stream), static_cast<uint32_t>(stream >> 32)};
  engine_.seed(seq);
}

double SceneRandom::Uniform(double lo, double hi) {
  const double unit = static_cast<double>(engine_() >> 11) * 0x1.0p-53;  // [0, 1)
  return lo + (hi - lo) * unit;
}

double SceneRandom::Normal(double sigma) {
  const double u1 = 1.0 - Uniform(0.0, 1.0);  // (0, 1]
  const double u2 = Uniform(0.0, 1.0);
  return sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

int SceneRandom::Integer(int lo, int hi) {
  const int n = static_cast<int>(std::floor(Uniform(0.0, hi - lo + 1.0)));
  return lo + std::min(n, hi - lo);
}

bool SceneRandom::Bernoulli(double p) {
  return Uniform(0.0, 1.0) < p;
}

Segment2 PerturbSegment(const Segment2& s, double angle, double offset) {
  const Eigen::Vector2d mid = s.Mid();
  const Eigen::Rotation2Dd rotation(angle);
  Segment2 out{mid + rotation * (s.a - mid), mid + rotation * (s.b - mid)};
  const double length = out.Length();
  if (length > 0.0) {
    const Eigen::Vector2d dir = (out.b - out.a) / length;
    const Eigen::Vector2d normal(-dir.y(), dir.x());
    out.a += offset * normal;
    out.b += offset * normal;
  }
  return out;
}

std::vector<Segment2> FragmentSegment(const Segment2& s, double cut_a, double cut_b, double split,
                                      double gap) {
  std::vector<std::pair<double, double>> spans;
  if (gap > 0.0) {
    spans = {{cut_a, split - 0.5 * gap}, {split + 0.5 * gap, 1.0 - cut_b}};
  } else {
    spans = {{cut_a, 1.0 - cut_b}};
  }
  std::vector<Segment2> pieces;
  const Eigen::Vector2d d = s.b - s.a;
  for (const auto& [t0, t1] : spans) {
    if (t1 > t0) pieces.push_back({s.a + t0 * d, s.a + t1 * d});
  }
  return pieces;
}

}  // namespace linetrack

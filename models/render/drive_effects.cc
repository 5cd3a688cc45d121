#include "models/render/drive_effects.h"

#include <algorithm>
#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kMotionDepth = 2.0;       // metres: depth of the points ImageMotionPx moves
constexpr double kMinGainRatio = 1.25;     // a gain change moves the level at least this much
constexpr double kSightStep = 0.1;         // metres between checks of the line of sight
constexpr double kPersonHeightMin = 1.60;  // metres
constexpr double kPersonHeightMax = 1.90;  //
constexpr double kCrossingSearchS = 2.0;   // seconds around its time a crossing may move
constexpr int kCrossingSearchStep = 3;     // frames between the crossings tried
constexpr double kEmerge = 0.5;            // metres a walk goes on past the area (into a wall)

// Time of event k of n over [t0, t1]: uniformly in the middle half of the k-th equal slot.
double SlotTime(double t0, double t1, int k, int n, SeededDraws* draws) {
  const double slot = (t1 - t0) / n;
  return t0 + slot * (k + 0.25 + 0.5 * draws->Unit());
}

size_t NearestFrame(const std::vector<SequenceFrame>& frames, double t) {
  const auto it = std::lower_bound(frames.begin(), frames.end(), t,
                                   [](const SequenceFrame& f, double v) { return f.t < v; });
  if (it == frames.begin()) return 0;
  if (it == frames.end()) return frames.size() - 1;
  const size_t j = static_cast<size_t>(it - frames.begin());
  return (t - frames[j - 1].t) <= (frames[j].t - t) ? j - 1 : j;
}

// True when the floor segment from a to b stays in the area (no wall or obstacle crossed).
bool ClearSight(const NavigableArea& area, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kSightStep)));
  for (int i = 1; i <= n; ++i) {
    if (!area.Contains(a + (b - a) * (static_cast<double>(i) / n))) return false;
  }
  return true;
}

// Where the person crossing near time t crosses the camera's axis: frame and point; false when
// no frame within kCrossingSearchS has a free crossing point at any tried distance.
bool FindCrossing(const std::vector<SequenceFrame>& frames, double t, double distance,
                  const DriveEffectsOptions& options, const NavigableArea* area, size_t* frame,
                  Eigen::Vector2d* point) {
  const size_t centre = NearestFrame(frames, t);
  for (int shift = 0;; shift += kCrossingSearchStep) {
    bool any = false;
    for (const int sign : {1, -1}) {
      const long j = static_cast<long>(centre) + sign * shift;
      if (j < 0 || j >= static_cast<long>(frames.size())) continue;
      if (std::abs(frames[j].t - frames[centre].t) > kCrossingSearchS) continue;
      any = true;
      const RobotPose& cam = frames[j].camera;
      const Eigen::Vector2d eye(cam.x, cam.y), axis(std::cos(cam.heading), std::sin(cam.heading));
      for (double d = distance; d >= 0.6 * options.person_distance_min; d *= 0.8) {
        const Eigen::Vector2d p = eye + d * axis;
        if (area == nullptr || ClearSight(*area, eye, p)) {
          *frame = static_cast<size_t>(j);
          *point = p;
          return true;
        }
      }
      if (shift == 0) break;
    }
    if (!any) return false;
  }
}

// How far (metres, up to `limit`) one can walk from p along `direction` inside the area.
double ClearRun(const NavigableArea* area, const Eigen::Vector2d& p,
                const Eigen::Vector2d& direction, double limit) {
  if (area == nullptr) return limit;
  double run = 0.0;
  while (run + kSightStep <= limit && area->Contains(p + (run + kSightStep) * direction))
    run += kSightStep;
  return std::min(limit, run + kEmerge);
}

void PlanPeople(const std::vector<SequenceFrame>& frames, const DriveEffectsOptions& options,
                const NavigableArea* area, DriveEffects* out) {
  SeededDraws draws(HashCombine(options.seed, 0x9e091eull));
  const double t0 = frames.front().t, t1 = frames.back().t;
  for (int k = 0; k < options.people; ++k) {
    const double t = SlotTime(t0, t1, k, options.people, &draws);
    const double distance = draws.Uniform(options.person_distance_min, options.person_distance_max);
    const double side = draws.Unit() < 0.5 ? 1.0 : -1.0;
    const double height = draws.Uniform(kPersonHeightMin, kPersonHeightMax);
    size_t j = 0;
    Eigen::Vector2d p;
    if (!FindCrossing(frames, t, distance, options, area, &j, &p)) continue;
    const double heading = frames[j].camera.heading;
    const Eigen::Vector2d across(-std::sin(heading), std::cos(heading));  // camera's left
    // The walk stays in the area, reaching into a wall (a doorway) where the area ends.
    const Eigen::Vector2d direction = side * across;
    const double before = ClearRun(area, p, -direction, options.person_walk_half);
    const double after = ClearRun(area, p, direction, options.person_walk_half);
    PersonWalk walk;
    walk.velocity = options.person_speed * direction;
    walk.t_start = frames[j].t - before / options.person_speed;
    walk.t_end = frames[j].t + after / options.person_speed;
    walk.start = p - before * direction;
    walk.height = height;
    walk.look = HashCombine(options.seed, 0x10000ull + k);
    out->people.push_back(walk);
    out->person_crossing_t.push_back(frames[j].t);
  }
}

void PlanGain(double t0, double t1, const DriveEffectsOptions& options, DriveEffects* out) {
  SeededDraws draws(HashCombine(options.seed, 0x6a17ull));
  std::vector<double> times;
  for (int k = 0; k < options.exposure_changes; ++k)
    times.push_back(SlotTime(t0, t1, k, options.exposure_changes, &draws));
  double level = 1.0;
  out->gain = {{t0, level}};
  const double lo = std::log(options.gain_min), hi = std::log(options.gain_max);
  for (size_t k = 0; k < times.size(); ++k) {
    double next = level;
    for (int attempt = 0; attempt < 32; ++attempt) {
      next = std::exp(draws.Uniform(lo, hi));
      if (std::max(next / level, level / next) >= kMinGainRatio) break;
    }
    const bool ramp = k % 2 == 1;
    const double end_limit = k + 1 < times.size() ? times[k + 1] : t1;
    const double end = ramp ? std::min(times[k] + options.ramp_duration, end_limit) : times[k];
    out->gain.push_back({times[k], level});
    out->gain.push_back({end, next});
    level = next;
  }
}

}  // namespace

bool DriveEffectsOptions::Check(std::string* why) const {
  if (people < 0 || people > 1000 || blackouts < 0 || blackouts > 1000 || exposure_changes < 0 ||
      exposure_changes > 1000) {
    *why = "people, blackouts and exposure changes must be in [0, 1000]";
    return false;
  }
  if (!(person_distance_min > 0.2 && person_distance_min <= person_distance_max &&
        person_distance_max < 50.0) ||
      !(person_speed > 0.0 && person_speed < 10.0) ||
      !(person_walk_half > 0.0 && person_walk_half < 100.0)) {
    *why = "person distances must be in (0.2, 50) m (min <= max), speed in (0, 10) m/s";
    return false;
  }
  if (!(blackout_duration > 0.0 && blackout_duration < 60.0) ||
      !(ramp_duration > 0.0 && ramp_duration < 600.0)) {
    *why = "blackout and ramp durations must be in (0, 60) s and (0, 600) s";
    return false;
  }
  if (!(gain_min > 0.05 && gain_min < gain_max && gain_max <= 20.0) ||
      gain_max / gain_min < kMinGainRatio * kMinGainRatio) {
    *why = "gains must satisfy 0.05 < min < max <= 20 with max / min >= 1.5625";
    return false;
  }
  if (!(shutter >= 0.0 && shutter <= 1.0) || !(blur_step_px >= 0.1 && blur_step_px <= 100.0) ||
      max_shutter_samples < 1 || max_shutter_samples > 64) {
    *why = "shutter must be in [0, 1] s, blur step in [0.1, 100] px, samples in [1, 64]";
    return false;
  }
  return true;
}

double DriveEffects::GainAt(double t) const {
  if (gain.empty()) return 1.0;
  if (t < gain.front().t) return gain.front().gain;
  size_t i = 0;
  while (i + 1 < gain.size() && gain[i + 1].t <= t)
    ++i;
  if (i + 1 == gain.size()) return gain[i].gain;
  const double span = gain[i + 1].t - gain[i].t;
  return gain[i].gain + (t - gain[i].t) / span * (gain[i + 1].gain - gain[i].gain);
}

bool DriveEffects::CoveredAt(double t) const {
  return std::any_of(blackouts.begin(), blackouts.end(),
                     [t](const auto& b) { return t >= b.first && t < b.second; });
}

std::vector<RenderSurface> DriveEffects::PeopleAt(double t) const {
  std::vector<RenderSurface> out;
  for (const PersonWalk& walk : people) {
    const std::vector<RenderSurface> person = PersonSurfaces(walk, t);
    out.insert(out.end(), person.begin(), person.end());
  }
  return out;
}

DriveEffects PlanDriveEffects(const std::vector<SequenceFrame>& frames,
                              const DriveEffectsOptions& options, const NavigableArea* area) {
  std::string why;
  if (!options.Check(&why)) throw InputError("drive effects: " + why);
  DriveEffects out;
  if (frames.empty()) return out;
  const double t0 = frames.front().t, t1 = frames.back().t;
  PlanPeople(frames, options, area, &out);
  SeededDraws draws(HashCombine(options.seed, 0xb1ac0ull));
  for (int k = 0; k < options.blackouts; ++k) {
    const double start = SlotTime(t0, t1, k, options.blackouts, &draws);
    out.blackouts.emplace_back(start, start + options.blackout_duration);
  }
  if (options.exposure_changes > 0) PlanGain(t0, t1, options, &out);
  return out;
}

Eigen::Isometry3d CamFromWorldAt(const std::vector<SequenceFrame>& frames, double t) {
  if (frames.empty()) throw InputError("drive: no frames to interpolate");
  if (t <= frames.front().t) return frames.front().cam_from_world;
  if (t >= frames.back().t) return frames.back().cam_from_world;
  const auto it = std::upper_bound(frames.begin(), frames.end(), t,
                                   [](double v, const SequenceFrame& f) { return v < f.t; });
  const SequenceFrame& b = *it;
  const SequenceFrame& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  const Eigen::Isometry3d wa = a.cam_from_world.inverse(), wb = b.cam_from_world.inverse();
  const Eigen::Quaterniond qa(wa.linear()), qb(wb.linear());
  Eigen::Isometry3d world_from_cam = Eigen::Isometry3d::Identity();
  world_from_cam.linear() = qa.slerp(f, qb).toRotationMatrix();
  world_from_cam.translation() = (1.0 - f) * wa.translation() + f * wb.translation();
  return world_from_cam.inverse();
}

double ImageMotionPx(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                     const CameraIntrinsics& camera) {
  const Eigen::Isometry3d b_from_a = b * a.inverse();
  double largest = 0.0;
  for (const double fu : {0.1, 0.5, 0.9}) {
    for (const double fv : {0.1, 0.5, 0.9}) {
      const Eigen::Vector2d uv(fu * camera.width, fv * camera.height);
      const Eigen::Vector3d in_b = b_from_a * (kMotionDepth * camera.Ray(uv));
      if (in_b.z() < 0.05) return 1e3;  // beside or behind the camera: as large as can be
      largest = std::max(largest, (camera.Project(in_b) - uv).norm());
    }
  }
  return largest;
}

std::vector<Eigen::Isometry3d> ShutterPoses(const std::vector<SequenceFrame>& frames, size_t k,
                                            const CameraIntrinsics& camera,
                                            const DriveEffectsOptions& options, double* motion_px) {
  if (motion_px != nullptr) *motion_px = 0.0;
  if (!(options.shutter > 0.0)) return {frames[k].cam_from_world};
  const double t = frames[k].t, half = 0.5 * options.shutter;
  const double motion =
      ImageMotionPx(CamFromWorldAt(frames, t - half), CamFromWorldAt(frames, t + half), camera);
  if (motion_px != nullptr) *motion_px = motion;
  const int n = std::clamp(static_cast<int>(std::ceil(motion / options.blur_step_px)), 1,
                           options.max_shutter_samples);
  if (n == 1) return {frames[k].cam_from_world};
  std::vector<Eigen::Isometry3d> out;
  for (int i = 0; i < n; ++i)
    out.push_back(CamFromWorldAt(frames, t - half + options.shutter * (i + 0.5) / n));
  return out;
}

}  // namespace linetrack

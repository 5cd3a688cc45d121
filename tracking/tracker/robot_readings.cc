#include "tracking/tracker/robot_readings.h"

#include <algorithm>
#include <cmath>

#include "models/geometry.h"
#include "models/statistics.h"

namespace linetrack {

std::optional<RobotPose> InterpolatePrior(const std::vector<PriorRecord>& records, double t,
                                          double max_gap) {
  if (records.empty() || !std::isfinite(t)) return std::nullopt;
  const auto after = std::lower_bound(records.begin(), records.end(), t,
                                      [](const PriorRecord& r, double time) { return r.t < time; });
  if (after == records.begin()) {
    if (records.front().t - t <= max_gap) return records.front().pose;
    return std::nullopt;
  }
  if (after == records.end()) {
    if (t - records.back().t <= max_gap) return records.back().pose;
    return std::nullopt;
  }
  const PriorRecord& a = *(after - 1);
  const PriorRecord& b = *after;
  const double s = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
  RobotPose p;
  p.x = a.pose.x + s * (b.pose.x - a.pose.x);
  p.y = a.pose.y + s * (b.pose.y - a.pose.y);
  p.heading = WrapAngle(a.pose.heading + s * WrapAngle(b.pose.heading - a.pose.heading));
  p.height = a.pose.height + s * (b.pose.height - a.pose.height);
  p.tilt = a.pose.tilt + s * (b.pose.tilt - a.pose.tilt);
  p.roll = a.pose.roll + s * WrapAngle(b.pose.roll - a.pose.roll);
  return p;
}

std::optional<Eigen::Isometry3d> GroundTruthAt(const std::vector<StampedPose>& poses, double t,
                                               double tolerance) {
  if (poses.empty() || !std::isfinite(t)) return std::nullopt;
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const StampedPose& p, double time) { return p.t < time; });
  const StampedPose* best = nullptr;
  if (after != poses.end()) best = &*after;
  if (after != poses.begin() && (!best || t - (after - 1)->t < best->t - t)) best = &*(after - 1);
  if (!best || std::abs(best->t - t) > tolerance) return std::nullopt;
  return best->world_from_cam.inverse();
}

double MedianTimeStep(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<double> steps;
  for (size_t i = 1; i < times.size(); ++i)
    steps.push_back(times[i] - times[i - 1]);
  return QuantileNearestRank(steps, 0.5);
}

}  // namespace linetrack

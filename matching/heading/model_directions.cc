#include "matching/heading/model_directions.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "matching/heading/vanishing_geometry.h"
#include "models/errors.h"

namespace linetrack {

bool ModelDirectionOptions::Check(std::string* why) const {
  if (!(horizontal_tolerance_deg > 0.0 && horizontal_tolerance_deg < 45.0) ||
      !(merge_deg > 0.0 && merge_deg < 45.0) || !(min_share >= 0.0 && min_share < 1.0)) {
    *why =
        "model directions: horizontal_tolerance_deg and merge_deg in (0, 45), min_share in "
        "[0, 1)";
    return false;
  }
  return true;
}

namespace {

struct WeightedAngle {
  double angle = 0.0;  // [0, pi)
  double length = 0.0;
};

// Greedy clustering modulo pi: the longest remaining direction takes every direction within
// `merge` of it; the cluster's angle is the length-weighted circular mean (on doubled angles).
std::vector<WeightedAngle> Cluster(std::vector<WeightedAngle> items, double merge) {
  std::sort(items.begin(), items.end(),
            [](const WeightedAngle& a, const WeightedAngle& b) { return a.length > b.length; });
  std::vector<bool> used(items.size(), false);
  std::vector<WeightedAngle> clusters;
  for (size_t i = 0; i < items.size(); ++i) {
    if (used[i]) continue;
    double c = 0.0, s = 0.0, total = 0.0;
    for (size_t j = i; j < items.size(); ++j) {
      if (used[j] || std::abs(WrapCentred(items[j].angle - items[i].angle, kPi)) > merge) continue;
      used[j] = true;
      c += items[j].length * std::cos(2.0 * items[j].angle);
      s += items[j].length * std::sin(2.0 * items[j].angle);
      total += items[j].length;
    }
    clusters.push_back({WrapPositive(0.5 * std::atan2(s, c), kPi), total});
  }
  return clusters;
}

ModelDirections Sorted(std::vector<WeightedAngle> clusters) {
  std::sort(clusters.begin(), clusters.end(),
            [](const WeightedAngle& a, const WeightedAngle& b) { return a.angle < b.angle; });
  ModelDirections out;
  for (const WeightedAngle& c : clusters) {
    out.angles.push_back(c.angle);
    out.lengths.push_back(c.length);
  }
  return out;
}

}  // namespace

std::vector<double> ModelDirections::Symmetries(double tolerance) const {
  std::vector<double> shifts;
  if (angles.empty()) return {0.0};
  // Every symmetry maps angles[0] onto some angle: only those shifts are candidates.
  for (double target : angles) {
    const double delta = WrapPositive(target - angles.front(), kPi);
    const bool maps_onto = std::all_of(angles.begin(), angles.end(), [&](double a) {
      return std::any_of(angles.begin(), angles.end(), [&](double b) {
        return std::abs(WrapCentred(a + delta - b, kPi)) <= tolerance;
      });
    });
    if (maps_onto) shifts.push_back(delta);
  }
  std::sort(shifts.begin(), shifts.end());
  return shifts;
}

ModelDirections DominantDirections(const WireframeModel& model,
                                   const ModelDirectionOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(model.path() + ": " + why);
  const double max_rise = std::sin(DegToRad(options.horizontal_tolerance_deg));
  std::vector<WeightedAngle> edges;
  for (const ModelEdge& e : model.edges()) {
    const Eigen::Vector3d d = e.segment.b - e.segment.a;
    const double length = d.norm();
    if (length <= 0.0 || std::abs(d.z()) > max_rise * length) continue;
    edges.push_back({WrapPositive(std::atan2(d.y(), d.x()), kPi), length});
  }
  std::vector<WeightedAngle> clusters = Cluster(edges, DegToRad(options.merge_deg));
  const double total =
      std::accumulate(clusters.begin(), clusters.end(), 0.0,
                      [](double sum, const WeightedAngle& c) { return sum + c.length; });
  clusters.erase(
      std::remove_if(clusters.begin(), clusters.end(),
                     [&](const WeightedAngle& c) { return c.length < options.min_share * total; }),
      clusters.end());
  return Sorted(clusters);
}

ModelDirections DirectionsFromAngles(const std::vector<double>& angles, double merge) {
  std::vector<WeightedAngle> items;
  for (double a : angles)
    items.push_back({WrapPositive(a, kPi), 1.0});
  return Sorted(Cluster(items, merge));
}

}  // namespace linetrack

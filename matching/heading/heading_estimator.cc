#include "matching/heading/heading_estimator.h"

#include <algorithm>
#include <cmath>

#include "matching/heading/heading_vote.h"
#include "matching/heading/vanishing_geometry.h"
#include "models/errors.h"
#include "models/robot_pose.h"

namespace linetrack {

bool HeadingOptions::Check(std::string* why) const {
  const double positive[] = {
      endpoint_sigma_px, gate_sigmas,           min_gate_deg,        bin_deg,
      tilt_step_deg,     max_bearing_sigma_deg, peak_separation_deg, min_bearing_sigma_deg};
  for (double v : positive) {
    if (!std::isfinite(v) || v <= 0.0) {
      *why = "heading options: sigmas, gates, bin and tilt step must be finite and > 0";
      return false;
    }
  }
  if (!(outlier_probability > 0.0 && outlier_probability < 1.0)) {
    *why = "heading options: outlier_probability in (0, 1)";
    return false;
  }
  if (!(line_angle_sigma_deg >= 0.0 && line_angle_sigma_deg < 90.0) ||
      !(line_offset_sigma_px >= 0.0 && std::isfinite(line_offset_sigma_px))) {
    *why = "heading options: line_angle_sigma_deg in [0, 90), line_offset_sigma_px finite >= 0";
    return false;
  }
  if (!std::isfinite(min_length_px) || min_length_px < 0.0 || min_support < 1 ||
      min_tilt_support < 1 || max_hypotheses < 1 || refine_iterations < 1 || refine_rounds < 1) {
    *why = "heading options: min_length_px >= 0; supports, hypotheses, iterations and rounds >= 1";
    return false;
  }
  if (!(tilt_min_deg >= -89.0 && tilt_max_deg <= 89.0 && tilt_min_deg <= tilt_max_deg)) {
    *why = "heading options: tilt range within [-89, 89] degrees, min <= max";
    return false;
  }
  return true;
}

std::vector<double> HeadingCandidates::BestHeadings() const {
  std::vector<double> out;
  if (hypotheses.empty()) return out;
  for (const HeadingHypothesis& h : hypotheses) {
    if (h.support < hypotheses.front().support) continue;
    out.insert(out.end(), h.headings.begin(), h.headings.end());
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// The vote lines' assignment at the answer, refined in rounds: refine, then re-assign.
struct PeakFit {
  RotationFit fit;
  std::vector<int> assignment;
  int support = 0;
};

int HorizontalCount(const std::vector<int>& assignment) {
  return static_cast<int>(
      std::count_if(assignment.begin(), assignment.end(), [](int a) { return a > 0; }));
}

// Assignment at the peak of the vote: lines whose bearing falls within its gate of the peak.
std::vector<int> PeakAssignment(const std::vector<VoteLine>& lines,
                                const std::vector<bool>& vertical, double heading, double tilt,
                                const ModelDirections& directions, const HeadingOptions& options) {
  std::vector<int> out(lines.size(), -1);
  const double max_sigma = DegToRad(options.max_bearing_sigma_deg);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (vertical[i]) {
      out[i] = 0;
      continue;
    }
    const Bearing b = BearingAt(lines[i], tilt);
    if (b.sigma > max_sigma) continue;
    double best = std::max(options.gate_sigmas * b.sigma, DegToRad(options.min_gate_deg));
    for (size_t k = 0; k < directions.angles.size(); ++k) {
      const double r =
          std::abs(WrapCentred(HeadingFromBearing(directions.angles[k], b.alpha) - heading, kPi));
      if (r <= best) {
        best = r;
        out[i] = static_cast<int>(k) + 1;
      }
    }
  }
  return out;
}

PeakFit FitPeak(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                const ModelDirections& directions, const HeadingOptions& options,
                const RotationStart& start) {
  PeakFit peak;
  const std::vector<bool> vertical = VerticalInliers(lines, camera, start.tilt);
  peak.assignment = PeakAssignment(lines, vertical, start.heading, start.tilt, directions, options);
  RotationStart at = start;
  for (int round = 0; round < options.refine_rounds; ++round) {
    if (HorizontalCount(peak.assignment) == 0) break;
    const RefinementContext context{&lines, &camera, &directions, options.refine_iterations,
                                    options.outlier_probability};
    peak.fit = RefineRotation(context, peak.assignment, at);
    at.heading = peak.fit.heading;
    at.tilt = peak.fit.tilt;
    peak.assignment = AssignLines(lines, camera, at.heading, at.tilt, directions, options);
  }
  peak.fit.heading = WrapPositive(at.heading, kPi);
  peak.fit.tilt = at.tilt;
  peak.support = HorizontalCount(peak.assignment);
  return peak;
}

// The segments and what they are matched against.
struct VoteContext {
  const std::vector<VoteLine>& lines;
  const CameraIntrinsics& camera;
  const ModelDirections& directions;
  const HeadingOptions& options;
};

// The peaks of the heading vote at start.tilt, each refined, repeated ones (modulo the
// symmetries) and those with too little support dropped; the most supported first.
std::vector<PeakFit> FindPeaks(const VoteContext& v, RotationStart start,
                               const std::vector<double>& symmetries) {
  std::vector<bool> vertical;
  VerticalScore(v.lines, v.camera, start.tilt, v.options.outlier_probability, &vertical);
  HeadingAccumulator acc = VoteHeadings(v.lines, vertical, start.tilt, v.directions, v.options);
  std::vector<PeakFit> peaks;
  const double suppress = DegToRad(v.options.peak_separation_deg);
  for (int attempt = 0; attempt < 2 * v.options.max_hypotheses && acc.Max() > 0.0 &&
                        static_cast<int>(peaks.size()) < v.options.max_hypotheses;
       ++attempt) {
    start.heading = acc.Peak();
    // Later peaks keep the first one's tilt (estimated once, on the best evidence).
    if (!peaks.empty()) {
      start.tilt = peaks.front().fit.tilt;
      start.estimate_tilt = false;
    }
    PeakFit peak = FitPeak(v.lines, v.camera, v.directions, v.options, start);
    for (double delta : symmetries) {
      acc.Suppress(start.heading + delta, suppress);
      acc.Suppress(peak.fit.heading + delta, suppress);
    }
    const bool repeated = std::any_of(peaks.begin(), peaks.end(), [&](const PeakFit& p) {
      return std::any_of(symmetries.begin(), symmetries.end(), [&](double delta) {
        return std::abs(WrapCentred(p.fit.heading + delta - peak.fit.heading, kPi)) < suppress;
      });
    });
    if (peak.support >= v.options.min_support && !repeated) peaks.push_back(std::move(peak));
  }
  std::stable_sort(peaks.begin(), peaks.end(),
                   [](const PeakFit& a, const PeakFit& b) { return a.support > b.support; });
  return peaks;
}

HeadingHypothesis Hypothesis(const PeakFit& peak, const std::vector<double>& symmetries) {
  HeadingHypothesis h;
  h.heading = peak.fit.heading;
  h.heading_sigma = peak.fit.heading_sigma;
  h.support = peak.support;
  h.rms_sigmas = peak.fit.rms_sigmas;
  for (double delta : symmetries) {
    h.headings.push_back(WrapPositive(h.heading + delta, 2.0 * kPi));
    h.headings.push_back(WrapPositive(h.heading + delta + kPi, 2.0 * kPi));
  }
  std::sort(h.headings.begin(), h.headings.end());
  return h;
}

std::vector<VanishingPoint> VanishingPoints(const std::vector<VoteLine>& lines, const PeakFit& peak,
                                            const CameraIntrinsics& camera,
                                            const ModelDirections& directions) {
  const Eigen::Matrix3d rotation = CamFromWorldRotation(peak.fit.heading, peak.fit.tilt);
  std::vector<VanishingPoint> out;
  for (int a = 0; a <= static_cast<int>(directions.angles.size()); ++a) {
    VanishingPoint vp;
    for (size_t i = 0; i < lines.size(); ++i) {
      if (peak.assignment[i] == a) vp.lines.push_back(lines[i].index);
    }
    if (vp.lines.empty()) continue;
    vp.vertical = a == 0;
    vp.model_direction = a - 1;
    vp.direction_cam = rotation * AssignedDirection(a, directions);
    vp.pixel = VanishingPixel(camera, vp.direction_cam);
    if (!vp.vertical) {
      vp.bearing = WrapCentred(peak.fit.heading - directions.angles[a - 1], kPi);
    }
    out.push_back(vp);
  }
  return out;
}

}  // namespace

HeadingCandidates EstimateHeading(const std::vector<Segment2>& lines,
                                  const CameraIntrinsics& camera, std::optional<double> tilt,
                                  const ModelDirections& directions,
                                  const HeadingOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(why);
  if (directions.angles.empty()) throw InputError("heading: the model has no horizontal direction");
  if (tilt && !std::isfinite(*tilt)) throw InputError("heading: the tilt is not finite");
  HeadingCandidates out;
  const std::vector<VoteLine> vote_lines = PrepareVoteLines(lines, camera, options);
  out.lines_used = static_cast<int>(vote_lines.size());
  RotationStart start;
  start.estimate_tilt = !tilt.has_value();
  start.tilt = tilt ? *tilt : ScanTilt(vote_lines, camera, directions, options).tilt;
  const std::vector<double> symmetries = directions.Symmetries(DegToRad(options.min_gate_deg));
  const std::vector<PeakFit> peaks =
      FindPeaks({vote_lines, camera, directions, options}, start, symmetries);
  if (peaks.empty()) {
    out.reason = "fewer than " + std::to_string(options.min_support) +
                 " segments share a horizontal vanishing point of the model's directions";
    return out;
  }
  if (!tilt) {
    const std::vector<int>& a = peaks.front().assignment;
    const int agreeing =
        static_cast<int>(std::count_if(a.begin(), a.end(), [](int x) { return x >= 0; }));
    if (agreeing < options.min_tilt_support) {
      out.reason =
          "fewer than " + std::to_string(options.min_tilt_support) + " segments agree on a tilt";
      return out;
    }
  }
  for (const PeakFit& p : peaks)
    out.hypotheses.push_back(Hypothesis(p, symmetries));
  const PeakFit& best = peaks.front();
  out.found = true;
  out.tilt = best.fit.tilt;
  out.tilt_sigma = best.fit.tilt_sigma;
  out.tilt_estimated = !tilt.has_value();
  out.vertical_lines =
      static_cast<int>(std::count(best.assignment.begin(), best.assignment.end(), 0));
  out.vanishing_points = VanishingPoints(vote_lines, best, camera, directions);
  return out;
}

}  // namespace linetrack

#include "matching/verification.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "matching/edge_candidates.h"
#include "matching/hypothesis_trimming.h"
#include "matching/segment_distance.h"
#include "models/robot_pose.h"

namespace linetrack {
namespace {

// W with W^T W = covariance^-1 (the inverse of the Cholesky factor).
Eigen::Matrix2d Whitening(const Eigen::Matrix2d& covariance) {
  const Eigen::Matrix2d l = covariance.llt().matrixL();
  return l.inverse();
}

bool InsidePrior(const VerificationContext& context, const Pose3Dof& pose,
                 const PoseRefinementResult& refinement, const VerificationOptions& options) {
  if (context.area != nullptr &&
      !context.area->InsideWalls({pose.x, pose.y}, options.wall_margin_m)) {
    return false;
  }
  if (context.prior == nullptr) return true;
  const PriorRegion& prior = *context.prior;
  // The refinement holds a pose that would leave this region at its border (PoseBounds), outside
  // it by about softness^2 times the image cost's gradient: within these it is on the border.
  constexpr double kBorderToleranceM = 0.01;
  constexpr double kBorderToleranceRad = 1e-3;
  const double k = options.prior_margin_sigmas;
  const double margin = DegToRad(options.prior_margin_deg) + k * refinement.heading_sigma_rad;
  const double offset = std::abs(WrapAngle(pose.heading - prior.heading.Mid()));
  return std::hypot(pose.x - prior.centre.x(), pose.y - prior.centre.y()) <=
             prior.radius + options.prior_margin_m + k * refinement.position_sigma_m +
                 kBorderToleranceM &&
         offset <= 0.5 * prior.heading.Width() + margin + kBorderToleranceRad;
}

// The result of guided matching at a pose.
struct Assignment {
  std::vector<Candidate> assigned;  // each line at most once; fragments of an edge do not overlap
  std::vector<std::pair<int, int>> confident;
  double lines_nats = 0.0;
};

// Greedy assignment by likelihood ratio: each line to its best edge, unless a better line already
// covers the same stretch of that edge (fragments of one edge do not overlap). A pair is
// confident when its ratio exceeds every other explanation of its line (clutter, another edge)
// and every rival line over the same stretch by report_nats.
Assignment Assign(const VerificationContext& context, std::vector<Candidate> candidates,
                  const VerificationOptions& options) {
  const double overlap_tolerance = 3.0 * context.noise.offset_px;
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    if (a.fit.log_likelihood_ratio != b.fit.log_likelihood_ratio) {
      return a.fit.log_likelihood_ratio > b.fit.log_likelihood_ratio;
    }
    return std::make_pair(a.line, a.edge) < std::make_pair(b.line, b.edge);
  });
  Assignment out;
  std::vector<bool> line_used(context.lines->size(), false);
  for (const Candidate& c : candidates) {
    if (line_used[c.line]) continue;
    // Fragments of one edge's image do not overlap and lie on one line.
    const Segment2& piece = (*context.lines)[c.line].pixels;
    const bool blocked = std::any_of(out.assigned.begin(), out.assigned.end(), [&](const auto& a) {
      return a.edge == c.edge &&
             (SpansOverlap(a.fit, c.fit, overlap_tolerance) ||
              FragmentChiSquare((*context.lines)[a.line].pixels, piece,
                                context.noise.fragment_offset_px) > options.gate_chi2);
    });
    if (blocked) continue;
    line_used[c.line] = true;
    out.assigned.push_back(c);
    out.lines_nats += c.fit.log_likelihood_ratio;
  }
  for (const Candidate& a : out.assigned) {
    double rival = 0.0;  // clutter
    for (const Candidate& c : candidates) {
      if (c.line == a.line && c.edge != a.edge) rival = std::max(rival, c.fit.log_likelihood_ratio);
      if (c.edge == a.edge && c.line != a.line && SpansOverlap(a.fit, c.fit, overlap_tolerance)) {
        rival = std::max(rival, c.fit.log_likelihood_ratio);
      }
    }
    if (a.fit.log_likelihood_ratio - rival >= options.report_nats) {
      out.confident.emplace_back(a.edge, a.line);
    }
  }
  std::sort(out.confident.begin(), out.confident.end());
  return out;
}

std::vector<std::pair<int, int>> Pairs(const Assignment& assignment) {
  std::vector<std::pair<int, int>> pairs;
  for (const Candidate& c : assignment.assigned)
    pairs.emplace_back(c.edge, c.line);
  return pairs;
}

// Plausibility checks and the eq. 9 / eq. 10 distances of the pairs.
void Judge(const VerificationContext& context, const VerificationOptions& options,
           const std::vector<EdgeImage>& images, VerifiedPose* result) {
  std::vector<double> distances;
  std::set<int> edges;
  for (const auto& [e, l] : result->pairs) {
    edges.insert(e);
    distances.push_back(images[e].visible
                            ? SegmentDistance(images[e].image, (*context.lines)[l].pixels)
                            : std::numeric_limits<double>::infinity());
  }
  result->matched_edges = static_cast<int>(edges.size());
  double sum = 0.0;
  for (double d : distances)
    sum += d;
  result->mean_distance_px = distances.empty() ? std::numeric_limits<double>::infinity()
                                               : sum / static_cast<double>(distances.size());
  result->score_px =
      distances.empty()
          ? std::numeric_limits<double>::infinity()
          : PartialHausdorff(distances, std::min<int>(options.min_matches, distances.size()));
  const PoseRefinementResult& r = result->refinement;
  const bool enough_edges = result->matched_edges >= options.min_matches;
  const bool inside = enough_edges && InsidePrior(context, result->pose, r, options);
  const bool observable = !(r.position_sigma_m > options.max_position_sigma_m ||
                            r.heading_sigma_rad > DegToRad(options.max_heading_sigma_deg));
  const bool focal_ok =
      !(options.refinement.focal_prior_sigma > 0.0 &&
        std::abs(r.focal_scale - 1.0) > 4.0 * options.refinement.focal_prior_sigma);
  // Held at the prior's border by the refinement (PoseBounds): the image evidence of its pairs
  // puts the pose outside the prior, so the pose is the prior's rather than the lines' (a rival
  // only).
  const bool held = r.held_by_bounds;
  result->implausible_because = !enough_edges ? "too few edges"
                                : !inside     ? "outside the prior"
                                : !observable ? "unobservable"
                                : held        ? "held at the prior's border"
                                : !focal_ok   ? "focal scale"
                                              : "";
  result->plausible = result->implausible_because.empty();
  result->unobservable = inside && (!observable || held) && focal_ok;
}

}  // namespace

std::vector<LineMatch> ToLineMatches(const VerificationContext& context,
                                     const std::vector<std::pair<int, int>>& pairs) {
  std::vector<LineMatch> matches;
  matches.reserve(pairs.size());
  const double sigma_theta = DegToRad(context.noise.angle_deg);
  for (const auto& [e, l] : pairs) {
    const MatchEdge& edge = (*context.edges)[e];
    const ObservedLine& line = (*context.lines)[l];
    const double half = 0.5 * line.length_px;
    matches.push_back(
        {edge.a, edge.b, line.pixels,
         Whitening(EndpointNoiseCovariance(-half, half, context.noise.offset_px, sigma_theta))});
  }
  return matches;
}

LineFitModel FitModel(const VerificationContext& context, const VerificationOptions& options) {
  LineFitModel model;
  model.offset_px = context.noise.offset_px;
  model.angle_rad = DegToRad(context.noise.angle_deg);
  model.image_diagonal_px = std::hypot(context.camera->width, context.camera->height);
  model.gate_chi2 = options.gate_chi2;
  model.extent_sigmas = options.extent_sigmas;
  return model;
}

PoseRefinementOptions RefinementOptions(const VerificationContext& context,
                                        const VerificationOptions& options) {
  PoseRefinementOptions refinement = options.refinement;
  if (context.prior == nullptr) return refinement;
  const PriorRegion& prior = *context.prior;
  refinement.bounds.active = true;
  refinement.bounds.centre = prior.centre;
  refinement.bounds.radius_m = prior.radius + options.prior_margin_m;
  refinement.bounds.heading = prior.heading.Mid();
  refinement.bounds.half_width_rad =
      0.5 * prior.heading.Width() + DegToRad(options.prior_margin_deg);
  refinement.bounds.sigmas = options.prior_margin_sigmas;
  return refinement;
}

bool VerificationOptions::Check(std::string* why) const {
  if (!(gate_chi2 > 0.0) || !(extent_sigmas > 0.0) || guided_rounds < 1 || min_matches < 2 ||
      max_pair_tests < 1 || !(hypothesis_quantile >= 0.975 && hypothesis_quantile < 1.0) ||
      !(visibility_step_px > 0.0) || !(ambiguity_nats >= 0.0) || !(report_nats >= 0.0) ||
      !(max_unreported_leverage > 0.0 && max_unreported_leverage <= 1.0)) {
    *why =
        "verification: gates > 0, guided_rounds >= 1, min_matches >= 2, quantile in [0.975, 1), "
        "max_unreported_leverage in (0, 1]";
    return false;
  }
  return refinement.Check(why);
}

VerifiedPose RefineHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options) {
  VerifiedPose result;
  result.pairs = pairs;
  const std::vector<LineMatch> matches = ToLineMatches(context, pairs);
  const PoseRefinementOptions refinement = RefinementOptions(context, options);
  for (const Pose3Dof& start : starts) {
    const PoseRefinementResult r =
        RefinePose(matches, *context.camera, context.height, context.tilt, start, refinement);
    if (result.refinement.iterations == 0 || r.chi2 < result.refinement.chi2) {
      result.refinement = r;
    }
  }
  result.pose = result.refinement.pose;
  return result;
}

double HypothesisEvidence(const VerificationContext& context, const VerificationOptions& options,
                          const VerifiedPose& hypothesis) {
  const std::vector<EdgeImage> images = ProjectPairedEdges(
      context, hypothesis.pose, hypothesis.refinement.focal_scale, hypothesis.pairs);
  const LineFitModel model = FitModel(context, options);
  double total = 0.0;
  for (const auto& [e, l] : hypothesis.pairs) {
    if (!images[e].visible) continue;
    const LineFit fit =
        FitLine(images[e].image, (*context.lines)[l].pixels, Eigen::Matrix2d::Zero(), model);
    total += std::max(0.0, fit.log_likelihood_ratio - (*context.lines)[l].clutter_log_density);
  }
  return total;
}

std::vector<std::pair<int, int>> ConsensusSet(const VerificationContext& context,
                                              const VerificationOptions& options,
                                              const VerifiedPose& verified) {
  const double sigma_theta = DegToRad(context.noise.angle_deg);
  std::vector<Eigen::Matrix2d> whitening;
  for (const ObservedLine& line : *context.lines) {
    const double half = 0.5 * line.length_px;
    whitening.push_back(
        Whitening(EndpointNoiseCovariance(-half, half, context.noise.offset_px, sigma_theta)));
  }
  std::vector<std::pair<int, int>> consensus;
  const PoseView view = ViewOf(verified.pose, context.height, context.tilt);
  for (size_t e = 0; e < context.edges->size(); ++e) {
    const MatchEdge& edge = (*context.edges)[e];
    const Eigen::Vector3d image_line = ProjectedEdgeLine(edge.a, edge.b, *context.camera, view,
                                                         verified.refinement.focal_scale, nullptr);
    for (size_t l = 0; l < context.lines->size(); ++l) {
      const Segment2& s = (*context.lines)[l].pixels;
      const Eigen::Vector2d r(image_line.dot(Eigen::Vector3d(s.a.x(), s.a.y(), 1.0)),
                              image_line.dot(Eigen::Vector3d(s.b.x(), s.b.y(), 1.0)));
      if ((whitening[l] * r).squaredNorm() <= options.gate_chi2) {
        consensus.emplace_back(static_cast<int>(e), static_cast<int>(l));
      }
    }
  }
  return consensus;
}

VerifiedPose Rematch(const VerificationContext& context, const VerifiedPose& start,
                     const VerificationOptions& options, VerificationStats* stats) {
  const LineFitModel model = FitModel(context, options);
  VerifiedPose result = start;
  std::vector<std::pair<int, int>> previous;
  Assignment assignment;
  std::vector<EdgeImage> images;
  for (int round = 0;; ++round) {
    images = ProjectEdges(context, result.pose, result.refinement.focal_scale);
    CandidateQuery query;
    query.at = {result.pose, result.refinement.focal_scale};
    query.covariance = result.refinement.covariance;
    assignment = Assign(context, Candidates(context, images, model, query, stats), options);
    std::vector<std::pair<int, int>> pairs = Pairs(assignment);
    std::sort(pairs.begin(), pairs.end());
    if (pairs == previous || round == options.guided_rounds || pairs.size() < 2) break;
    result.refinement = RefinePose(ToLineMatches(context, pairs), *context.camera, context.height,
                                   context.tilt, {result.pose, result.refinement.focal_scale},
                                   RefinementOptions(context, options));
    result.pose = result.refinement.pose;
    previous = std::move(pairs);
  }
  result.pairs = Pairs(assignment);
  result.confident_pairs = assignment.confident;
  result.evidence = PoseEvidence();
  result.evidence.lines_nats = assignment.lines_nats;
  result.evidence_complete = false;
  Judge(context, options, images, &result);
  return result;
}

VerifiedPose VerifyHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options) {
  VerifiedPose hypothesis = RefineHypothesis(context, pairs, starts, options);
  if (!TrimHypothesis(context, options, &hypothesis)) {
    hypothesis.implausible_because = "inconsistent hypothesis";
    return hypothesis;
  }
  return Rematch(context, hypothesis, options);
}

void CompleteEvidence(const VerificationContext& context, const VerificationOptions& options,
                      VerifiedPose* verified) {
  if (verified->evidence_complete) return;
  const std::vector<EdgeImage> images =
      ProjectEdges(context, verified->pose, verified->refinement.focal_scale);
  const LineFitModel model = FitModel(context, options);
  // Spans of the assigned lines along their edges' images.
  std::vector<std::vector<std::pair<double, double>>> spans(images.size());
  for (const auto& [e, l] : verified->pairs) {
    if (!images[e].visible) continue;
    const LineFit fit =
        FitLine(images[e].image, (*context.lines)[l].pixels, Eigen::Matrix2d::Zero(), model);
    spans[e].emplace_back(fit.lo, fit.hi);
  }
  const Eigen::Vector3d eye(verified->pose.x, verified->pose.y, context.height);
  const CameraIntrinsics camera = ScaledCamera(*context.camera, verified->refinement.focal_scale);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(verified->pose, context));
  const double log_detected = std::log(context.noise.detection_probability);
  const double log_missed = std::log(1.0 - context.noise.detection_probability);
  PoseEvidence& evidence = verified->evidence;
  evidence.edges_nats = evidence.predicted_px = evidence.covered_px = 0.0;
  for (size_t e = 0; e < images.size(); ++e) {
    const EdgeImage& image = images[e];
    if (!image.visible) continue;
    const double length = image.image.Length();
    const Eigen::Vector2d axis = (image.image.b - image.image.a) / length;
    // Position along the image of the point at parameter t of the clipped world segment.
    auto along = [&](double t) {
      const Eigen::Vector3d point = image.world.a + t * (image.world.b - image.world.a);
      return (camera.Project(cam_from_world * point) - image.image.a).dot(axis);
    };
    const int samples =
        std::max(1, static_cast<int>(std::ceil(length / options.visibility_step_px)));
    double visible = 0.0, covered = 0.0, start = 0.0;
    for (int k = 0; k < samples; ++k) {
      const double end = k + 1 == samples ? length : along((k + 1.0) / samples);
      const double t = (k + 0.5) / samples;
      if (context.occlusion == nullptr ||
          !context.occlusion->Blocked(eye, image.world.a + t * (image.world.b - image.world.a))) {
        visible += end - start;
        const double middle = 0.5 * (start + end);
        const bool is_covered = std::any_of(spans[e].begin(), spans[e].end(), [&](const auto& s) {
          return middle >= s.first && middle <= s.second;
        });
        covered += is_covered ? end - start : 0.0;
      }
      start = end;
    }
    if (visible < options.min_detectable_px) continue;
    const double fraction = std::min(1.0, covered / visible);
    evidence.predicted_px += visible;
    evidence.covered_px += std::min(covered, visible);
    evidence.edges_nats += fraction * log_detected + (1.0 - fraction) * log_missed;
  }
  verified->evidence_complete = true;
}

bool SameRefinedPose(const Pose3Dof& a, double scale_a, const Pose3Dof& b, double scale_b) {
  return std::abs(a.x - b.x) <= 0.01 && std::abs(a.y - b.y) <= 0.01 &&
         std::abs(WrapAngle(a.heading - b.heading)) <= DegToRad(0.1) &&
         std::abs(scale_a - scale_b) <= 1e-3;
}

}  // namespace linetrack

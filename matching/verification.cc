#include "matching/verification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "matching/segment_distance.h"
#include "models/robot_pose.h"

namespace linetrack {
namespace {

RobotPose Full(const Pose3Dof& pose, const VerificationContext& context) {
  return {pose.x, pose.y, pose.heading, context.height, context.tilt};
}

// Angle (radians, in [0, pi/2]) between the directions of two segments.
double AngleBetween(const Segment2& a, const Segment2& b) {
  const Eigen::Vector2d da = (a.b - a.a).normalized(), db = (b.b - b.a).normalized();
  return std::acos(std::min(1.0, std::abs(da.dot(db))));
}

std::vector<LineMatch> ToLineMatches(const VerificationContext& context,
                                     const std::vector<std::pair<int, int>>& pairs) {
  std::vector<LineMatch> matches;
  matches.reserve(pairs.size());
  for (const auto& [e, l] : pairs) {
    const MatchEdge& edge = (*context.edges)[e];
    matches.push_back({edge.a, edge.b, (*context.lines)[l].pixels});
  }
  return matches;
}

// The camera with its focal lengths scaled by `scale` (the estimated calibration error).
CameraIntrinsics ScaledCamera(const CameraIntrinsics& camera, double scale) {
  CameraIntrinsics c = camera;
  c.px *= scale;
  c.py *= scale;
  return c;
}

// Projects every candidate edge at `pose` (frustum-clipped, no occlusion); empty segments for
// edges out of view.
std::vector<std::optional<Segment2>> ProjectEdges(const VerificationContext& context,
                                                  const Pose3Dof& pose, double focal_scale) {
  const CameraIntrinsics camera = ScaledCamera(*context.camera, focal_scale);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(pose, context));
  std::vector<std::optional<Segment2>> out;
  out.reserve(context.edges->size());
  for (const MatchEdge& edge : *context.edges) {
    Segment3 s{edge.a, edge.b};
    if (!ClipToFrustum(cam_from_world, camera, 0.05, &s)) {
      out.emplace_back();
      continue;
    }
    out.push_back(
        Segment2{camera.Project(cam_from_world * s.a), camera.Project(cam_from_world * s.b)});
  }
  return out;
}

bool InsidePrior(const VerificationContext& context, const Pose3Dof& pose,
                 const VerificationOptions& options) {
  if (context.area != nullptr &&
      !context.area->InsideWalls({pose.x, pose.y}, options.wall_margin_m)) {
    return false;
  }
  if (context.prior == nullptr) return true;
  const PriorRegion& prior = *context.prior;
  const double margin = DegToRad(options.prior_margin_deg);
  const double offset = std::abs(WrapAngle(pose.heading - prior.heading.Mid()));
  return std::hypot(pose.x - prior.centre.x(), pose.y - prior.centre.y()) <=
             prior.radius + options.prior_margin_m &&
         offset <= 0.5 * prior.heading.Width() + margin;
}

// The point of `edge` seen at the middle of the observed segment: the closest point of the edge
// to the viewing ray through that pixel (world coordinates).
Eigen::Vector3d PointSeenOnEdge(const MatchEdge& edge, const Segment2& observed,
                                const Eigen::Isometry3d& cam_from_world, const Eigen::Vector3d& eye,
                                const CameraIntrinsics& camera) {
  const Eigen::Vector3d ray = cam_from_world.linear().transpose() * camera.Ray(observed.Mid());
  const Eigen::Vector3d w0 = eye - edge.a;
  const Eigen::Vector3d d = edge.b - edge.a;
  const double a = ray.dot(ray), b = ray.dot(d), c = d.dot(d);
  const double p = ray.dot(w0), q = d.dot(w0);
  const double denom = a * c - b * b;
  const double t = denom > 1e-12 ? std::clamp((a * q - b * p) / denom, 0.0, 1.0) : 0.5;
  return edge.a + t * d;
}

// A line near an edge: (edge index, line index) and its eq. 9 distance (pixels).
struct Claim {
  int edge = -1;
  int line = -1;
  double distance = 0.0;
};

// Two lines near the same edge over the same stretch cannot both be its image (fragments of one
// edge do not overlap). A claim with no such rival is confident; with rivals that all fit much
// worse (distance over twice its own plus a pixel) it is the clear winner, good enough for the
// pose but not reported (the clutter may be the better fit); otherwise it is dropped. A wrong
// correspondence is worse than a missing one. `rivals` are all lines near visible edges.
void SortClaims(const std::vector<std::optional<Segment2>>& projected,
                const std::vector<ObservedLine>& lines, double overlap_px,
                const std::vector<Claim>& rivals, const std::vector<Claim>& claims,
                GuidedMatching* out) {
  auto overlap = [&](int edge_index, int line_a, int line_b) {
    const Segment2& edge = *projected[edge_index];
    const Eigen::Vector2d axis = (edge.b - edge.a).normalized();
    auto span = [&](const Segment2& s) {
      const double t0 = (s.a - edge.a).dot(axis), t1 = (s.b - edge.a).dot(axis);
      return std::make_pair(std::min(t0, t1), std::max(t0, t1));
    };
    const auto a = span(lines[line_a].pixels), b = span(lines[line_b].pixels);
    return std::min(a.second, b.second) - std::max(a.first, b.first);
  };
  for (const Claim& claim : claims) {
    bool rivalled = false, contested = false;
    for (const Claim& rival : rivals) {
      if (rival.edge != claim.edge || rival.line == claim.line ||
          overlap(claim.edge, claim.line, rival.line) <= overlap_px) {
        continue;
      }
      rivalled = true;
      contested = contested || rival.distance <= 2.0 * claim.distance + 1.0;
    }
    if (contested) continue;
    out->for_pose.emplace_back(claim.edge, claim.line);
    if (!rivalled) out->confident.emplace_back(claim.edge, claim.line);
  }
}

// Extra distance (pixels, 3 sigma) a calibration error may put between a line and its edge's
// projection: 3 focal_relative r, r the farthest endpoint's distance from the principal point.
double CalibrationAllowance(const VerificationContext& context, const Segment2& s) {
  const Eigen::Vector2d centre(context.camera->u0, context.camera->v0);
  return 3.0 * context.focal_relative * std::max((s.a - centre).norm(), (s.b - centre).norm());
}

// Matched edges, distances (eq. 9, eq. 10) and plausibility of the pairs at the pose.
void Score(const VerificationContext& context, const VerificationOptions& options,
           VerifiedPose* result) {
  const std::vector<std::optional<Segment2>> projected =
      ProjectEdges(context, result->pose, result->refinement.focal_scale);
  std::vector<double> distances;
  std::set<int> edges;
  // Sums of d / max(mean distance, calibration allowance) and of the allowances.
  double relative = 0.0, allowance = 0.0;
  for (const auto& [e, l] : result->pairs) {
    edges.insert(e);
    const Segment2& line = (*context.lines)[l].pixels;
    const double a = CalibrationAllowance(context, line);
    distances.push_back(projected[e] ? SegmentDistance(*projected[e], line)
                                     : std::numeric_limits<double>::infinity());
    relative += distances.back() / std::hypot(options.max_mean_distance_px, a);
    allowance += a;
  }
  const double n = std::max<double>(1.0, distances.size());
  result->matched_edges = static_cast<int>(edges.size());
  double sum = 0.0;
  for (double d : distances)
    sum += d;
  result->mean_distance_px = distances.empty() ? std::numeric_limits<double>::infinity()
                                               : sum / static_cast<double>(distances.size());
  result->score_px =
      PartialHausdorff(distances, std::min<int>(options.min_matches, distances.size()));
  const PoseRefinementResult& r = result->refinement;
  result->implausible_because.clear();
  if (relative / n > 1.0) {
    result->implausible_because = "mean distance";
  } else if (!InsidePrior(context, result->pose, options)) {
    result->implausible_because = "outside the prior";
  } else if (result->matched_edges < options.min_matches) {
    result->implausible_because = "too few edges";
  } else if (r.rms_px > std::hypot(options.max_rms_px, 0.5 * allowance / n)) {
    result->implausible_because = "rms";
  } else if (r.position_sigma_m > options.max_position_sigma_m ||
             r.heading_sigma_rad > DegToRad(options.max_heading_sigma_deg)) {
    result->implausible_because = "unobservable";
  } else if (std::abs(r.focal_scale - 1.0) > 3.0 * options.refinement.focal_prior_sigma) {
    result->implausible_because = "focal scale";
  }
  result->plausible = result->implausible_because.empty();
}

}  // namespace

bool VerificationOptions::Check(std::string* why) const {
  if (!(match_distance_px > 0.0) || !(match_angle_deg > 0.0) || guided_rounds < 0 ||
      !(max_rms_px > 0.0) || min_matches < 2 || !(min_support >= 0.0 && min_support <= 1.0)) {
    *why = "verification: thresholds must be positive, min_matches >= 2, min_support in [0, 1]";
    return false;
  }
  return refinement.Check(why);
}

GuidedMatching GuidedMatches(const VerificationContext& context, const Pose3Dof& pose,
                             double focal_scale, const VerificationOptions& options) {
  const std::vector<std::optional<Segment2>> projected = ProjectEdges(context, pose, focal_scale);
  const CameraIntrinsics camera = ScaledCamera(*context.camera, focal_scale);
  const double max_angle = DegToRad(options.match_angle_deg);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(pose, context));
  const Eigen::Vector3d eye(pose.x, pose.y, context.height);
  std::vector<Claim> claims, rivals;
  std::vector<std::pair<double, int>> near;  // (distance, edge) under the thresholds
  for (size_t l = 0; l < context.lines->size(); ++l) {
    const Segment2& observed = (*context.lines)[l].pixels;
    const double match_distance =
        std::hypot(options.match_distance_px, CalibrationAllowance(context, observed));
    const double rival_distance = options.rival_factor * match_distance;
    near.clear();
    for (size_t e = 0; e < projected.size(); ++e) {
      if (!projected[e] || AngleBetween(*projected[e], observed) > max_angle) continue;
      const double d = SegmentDistance(*projected[e], observed);
      if (d < rival_distance) near.emplace_back(d, static_cast<int>(e));
    }
    std::sort(near.begin(), near.end());
    // The nearest edge not hidden where the line lies claims it, unless another visible edge
    // is nearly as near (two edges aligned in the image: the line cannot tell them apart).
    int claimed = -1, visible = 0;
    for (const auto& [d, e] : near) {
      if (context.occlusion != nullptr &&
          context.occlusion->Blocked(
              eye, PointSeenOnEdge((*context.edges)[e], observed, cam_from_world, eye, camera))) {
        continue;
      }
      rivals.push_back({e, static_cast<int>(l), d});
      if (visible++ == 0 && d < match_distance) claimed = e;
    }
    // Exactly one visible edge near the line, and near enough: it is the last rival pushed.
    if (claimed >= 0 && visible == 1) claims.push_back(rivals.back());
  }
  GuidedMatching matching;
  SortClaims(projected, *context.lines, options.overlap_px, rivals, claims, &matching);
  return matching;
}

VerifiedPose Rematch(const VerificationContext& context, const VerifiedPose& start,
                     const VerificationOptions& options) {
  VerifiedPose result = start;
  for (int round = 0; round < options.guided_rounds; ++round) {
    if (result.refinement.rms_px > 3.0 * options.max_rms_px) break;  // hopeless: skip re-matching
    GuidedMatching guided =
        GuidedMatches(context, result.pose, result.refinement.focal_scale, options);
    if (guided.for_pose.size() < 2) break;
    result.refinement =
        RefinePose(ToLineMatches(context, guided.for_pose), *context.camera, context.height,
                   context.tilt, result.pose, result.refinement.focal_scale, options.refinement);
    result.pairs = std::move(guided.for_pose);
    result.confident_pairs = std::move(guided.confident);
    result.pose = result.refinement.pose;
  }
  Score(context, options, &result);
  return result;
}

VerifiedPose RefineHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options) {
  VerifiedPose result;
  result.pairs = pairs;
  const std::vector<LineMatch> matches = ToLineMatches(context, pairs);
  for (const Pose3Dof& start : starts) {
    const PoseRefinementResult r = RefinePose(matches, *context.camera, context.height,
                                              context.tilt, start, options.refinement);
    if (result.refinement.iterations == 0 || r.rms_px < result.refinement.rms_px) {
      result.refinement = r;
    }
  }
  result.pose = result.refinement.pose;
  return result;
}

VerifiedPose VerifyHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs,
                              const std::vector<Pose3Dof>& starts,
                              const VerificationOptions& options) {
  return Rematch(context, RefineHypothesis(context, pairs, starts, options), options);
}

bool BetterThan(const VerifiedPose& a, const VerifiedPose& b) {
  if (a.plausible != b.plausible) return a.plausible;
  if (a.matched_edges != b.matched_edges) return a.matched_edges > b.matched_edges;
  return a.mean_distance_px < b.mean_distance_px;
}

PoseEvidence Evidence(const VerificationContext& context, const WireframeModel& model,
                      const OcclusionTester& occlusion, const VerifiedPose& verified,
                      const VerificationOptions& options) {
  EdgeProjectionOptions projection;
  projection.sample_step_px = 6.0;
  projection.min_length_px = 2.0;
  const std::vector<ProjectedEdge> pieces = ProjectVisibleEdges(
      model, occlusion, CamFromWorld(Full(verified.pose, context)),
      ScaledCamera(*context.camera, verified.refinement.focal_scale), projection);
  std::map<int, double> visible_length;
  for (const ProjectedEdge& p : pieces)
    visible_length[p.edge_id] += p.image.Length();
  // A line supports a visible piece when it lies near it (eq. 9 distance and angle), weighted by
  // exp(-d^2 / 2 sigma^2): evidence depends on the pose only, not on which lines were kept as
  // correspondences, and a close fit counts more than a loose one.
  const double max_angle = DegToRad(options.support_angle_deg);
  const size_t num_lines = context.lines->size();
  std::vector<double> weight_of_line(num_lines, 0.0);
  PoseEvidence evidence;
  for (const ProjectedEdge& p : pieces) {
    const bool counted = visible_length[p.edge_id] >= options.support_min_length_px;
    const double length = p.image.Length();
    const Eigen::Vector2d axis = (p.image.b - p.image.a) / length;
    double piece_covered = 0.0, piece_weighted = 0.0;
    for (size_t l = 0; l < num_lines; ++l) {
      const Segment2& s = (*context.lines)[l].pixels;
      if (AngleBetween(p.image, s) > max_angle) continue;
      const double d = SegmentDistance(p.image, s);
      const double allowance = CalibrationAllowance(context, s);
      if (d > std::hypot(options.support_distance_px, allowance)) continue;
      const double sigma = std::hypot(options.evidence_sigma_px, allowance / 3.0);
      const double w = std::exp(-0.5 * d * d / (sigma * sigma));
      weight_of_line[l] = std::max(weight_of_line[l], w);
      double t0 = (s.a - p.image.a).dot(axis), t1 = (s.b - p.image.a).dot(axis);
      if (t0 > t1) std::swap(t0, t1);
      const double overlap = std::max(0.0, std::min(t1, length) - std::max(t0, 0.0));
      piece_covered += overlap;
      piece_weighted += w * overlap;
    }
    if (!counted) continue;
    evidence.predicted_px += length;
    evidence.covered_px += std::min(piece_covered, length);
    evidence.fitted_px += std::min(piece_weighted, length);
  }
  for (size_t l = 0; l < num_lines; ++l) {
    evidence.explained_px +=
        weight_of_line[l] * ((*context.lines)[l].pixels.Length() + options.line_bonus_px);
  }
  return evidence;
}

}  // namespace linetrack

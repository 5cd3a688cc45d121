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

// Projects every candidate edge at `pose` (frustum-clipped, no occlusion); empty segments for
// edges out of view.
std::vector<std::optional<Segment2>> ProjectEdges(const VerificationContext& context,
                                                  const Pose3Dof& pose) {
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(pose, context));
  std::vector<std::optional<Segment2>> out;
  out.reserve(context.edges->size());
  for (const MatchEdge& edge : *context.edges) {
    Segment3 s{edge.a, edge.b};
    if (!ClipToFrustum(cam_from_world, *context.camera, 0.05, &s)) {
      out.emplace_back();
      continue;
    }
    out.push_back(Segment2{context.camera->Project(cam_from_world * s.a),
                           context.camera->Project(cam_from_world * s.b)});
  }
  return out;
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

VerifiedPose VerifyHypothesis(const VerificationContext& context,
                              const std::vector<std::pair<int, int>>& pairs, const Pose3Dof& start,
                              const VerificationOptions& options) {
  VerifiedPose result;
  result.pairs = pairs;
  result.refinement = RefinePose(ToLineMatches(context, pairs), *context.camera, context.height,
                                 context.tilt, start, options.refinement);
  result.pose = result.refinement.pose;
  const double max_angle = DegToRad(options.match_angle_deg);
  for (int round = 0; round < options.guided_rounds; ++round) {
    if (result.refinement.rms_px > 3.0 * options.max_rms_px) break;  // hopeless: skip re-matching
    const std::vector<std::optional<Segment2>> projected = ProjectEdges(context, result.pose);
    std::vector<std::pair<int, int>> guided;
    for (size_t l = 0; l < context.lines->size(); ++l) {
      const Segment2& observed = (*context.lines)[l].pixels;
      int best = -1;
      double best_distance = options.match_distance_px;
      for (size_t e = 0; e < projected.size(); ++e) {
        if (!projected[e] || AngleBetween(*projected[e], observed) > max_angle) continue;
        const double d = SegmentDistance(*projected[e], observed);
        if (d < best_distance) best_distance = d, best = static_cast<int>(e);
      }
      if (best >= 0) guided.emplace_back(best, static_cast<int>(l));
    }
    if (guided.size() < 2) break;
    const PoseRefinementResult refined =
        RefinePose(ToLineMatches(context, guided), *context.camera, context.height, context.tilt,
                   result.pose, options.refinement);
    result.pairs = std::move(guided);
    result.refinement = refined;
    result.pose = refined.pose;
  }
  // Score the final pairs at the final pose.
  const std::vector<std::optional<Segment2>> projected = ProjectEdges(context, result.pose);
  std::vector<double> distances;
  std::set<int> edges;
  for (const auto& [e, l] : result.pairs) {
    edges.insert(e);
    distances.push_back(projected[e] ? SegmentDistance(*projected[e], (*context.lines)[l].pixels)
                                     : std::numeric_limits<double>::infinity());
  }
  result.matched_edges = static_cast<int>(edges.size());
  double sum = 0.0;
  for (double d : distances)
    sum += d;
  result.mean_distance_px = distances.empty() ? std::numeric_limits<double>::infinity()
                                              : sum / static_cast<double>(distances.size());
  result.score_px =
      PartialHausdorff(distances, std::min<int>(options.min_matches, distances.size()));
  result.plausible = result.matched_edges >= options.min_matches &&
                     result.refinement.rms_px <= options.max_rms_px &&
                     result.refinement.position_sigma_m <= options.max_position_sigma_m &&
                     result.refinement.heading_sigma_rad <= DegToRad(options.max_heading_sigma_deg);
  return result;
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
      model, occlusion, CamFromWorld(Full(verified.pose, context)), *context.camera, projection);
  PoseEvidence evidence;
  std::map<int, std::vector<const Segment2*>> lines_of_edge;  // model edge id -> observed lines
  for (const auto& [e, l] : verified.pairs) {
    const Segment2& line = (*context.lines)[l].pixels;
    lines_of_edge[(*context.edges)[e].edge_id].push_back(&line);
    evidence.explained_px += line.Length();
  }
  std::map<int, double> visible_length;
  for (const ProjectedEdge& p : pieces)
    visible_length[p.edge_id] += p.image.Length();
  for (const ProjectedEdge& p : pieces) {
    if (visible_length[p.edge_id] < options.support_min_length_px) continue;
    const double length = p.image.Length();
    evidence.predicted_px += length;
    const auto it = lines_of_edge.find(p.edge_id);
    if (it == lines_of_edge.end()) continue;
    // Overlap of the observed lines with the piece, measured along the piece.
    const Eigen::Vector2d axis = (p.image.b - p.image.a) / length;
    double piece_covered = 0.0;
    for (const Segment2* s : it->second) {
      double t0 = (s->a - p.image.a).dot(axis), t1 = (s->b - p.image.a).dot(axis);
      if (t0 > t1) std::swap(t0, t1);
      piece_covered += std::max(0.0, std::min(t1, length) - std::max(t0, 0.0));
    }
    evidence.covered_px += std::min(piece_covered, length);
  }
  return evidence;
}

}  // namespace linetrack

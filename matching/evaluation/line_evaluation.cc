#include "matching/evaluation/line_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "matching/lines/segment_fitting.h"
#include "matching/lines/undistortion.h"

namespace linetrack {

bool DetectionMatchOptions::Check(std::string* why) const {
  if (!(max_angle_deg >= 0.0 && max_angle_deg < 90.0 && max_offset_px >= 0.0 &&
        end_margin_px >= 0.0 && std::isfinite(max_offset_px + end_margin_px))) {
    *why = "detection match tolerances must be finite, >= 0, angle below 90 degrees";
    return false;
  }
  if (!(min_coverage >= 0.0 && min_coverage <= 1.0)) {
    *why = "min_coverage must be in [0, 1]";
    return false;
  }
  return true;
}

namespace {

// Positions of the detection's endpoints along the edge (pixels from edge.a), sorted.
std::pair<double, double> ExtentAlong(const Segment2& edge, const Segment2& detection) {
  const Eigen::Vector2d d = (edge.b - edge.a).normalized();
  const double t1 = (detection.a - edge.a).dot(d), t2 = (detection.b - edge.a).dot(d);
  return {std::min(t1, t2), std::max(t1, t2)};
}

}  // namespace

bool DetectionOnEdge(const Segment2& edge, const Segment2& detection,
                     const DetectionMatchOptions& options) {
  const double length = edge.Length();
  if (length <= 0.0 || detection.Length() <= 0.0) return false;
  if (LineAngle(edge, detection) > DegToRad(options.max_angle_deg)) return false;
  const Eigen::Vector2d d = (edge.b - edge.a) / length;
  if (std::abs(Cross2(d, detection.a - edge.a)) > options.max_offset_px ||
      std::abs(Cross2(d, detection.b - edge.a)) > options.max_offset_px) {
    return false;
  }
  // Some of the detection lies within the edge's extent (with the margin); a detection running
  // on past the edge along the same image line (collinear edges, bridged gaps) still images it.
  const auto [t1, t2] = ExtentAlong(edge, detection);
  return std::min(t2, length + options.end_margin_px) - std::max(t1, -options.end_margin_px) > 0.0;
}

double EdgeCoverage(const Segment2& edge, const std::vector<Segment2>& detections) {
  const double length = edge.Length();
  if (length <= 0.0) return 0.0;
  std::vector<std::pair<double, double>> intervals;
  for (const Segment2& s : detections) {
    auto [t1, t2] = ExtentAlong(edge, s);
    t1 = std::max(t1, 0.0);
    t2 = std::min(t2, length);
    if (t2 > t1) intervals.emplace_back(t1, t2);
  }
  std::sort(intervals.begin(), intervals.end());
  double covered = 0.0, reach = 0.0;
  for (const auto& [t1, t2] : intervals) {
    const double start = std::max(t1, reach);
    if (t2 > start) covered += t2 - start;
    reach = std::max(reach, t2);
  }
  return covered / length;
}

DetectionEvaluation EvaluateDetections(const std::vector<ProjectedEdge>& truth,
                                       const std::vector<Segment2>& detections,
                                       double min_edge_length_px,
                                       const DetectionMatchOptions& options) {
  std::vector<ObservablePiece> pieces(truth.size());
  for (size_t i = 0; i < truth.size(); ++i)
    pieces[i].edge = truth[i];
  return EvaluateDetections(pieces, detections, min_edge_length_px, options);
}

DetectionEvaluation EvaluateDetections(const std::vector<ObservablePiece>& truth,
                                       const std::vector<Segment2>& detections,
                                       double min_edge_length_px,
                                       const DetectionMatchOptions& options) {
  DetectionEvaluation evaluation;
  for (const ObservablePiece& observable : truth) {
    const ProjectedEdge& piece = observable.edge;
    if (piece.image.Length() < min_edge_length_px) continue;
    EdgeDetection e;
    e.edge_id = piece.edge_id;
    e.edge = piece.image;
    std::vector<Segment2> along;
    for (size_t i = 0; i < detections.size(); ++i) {
      if (DetectionOnEdge(piece.image, detections[i], options)) {
        e.detections.push_back(static_cast<int>(i));
        along.push_back(detections[i]);
      }
    }
    e.coverage = EdgeCoverage(piece.image, along);
    e.found = !along.empty() && e.coverage >= options.min_coverage;
    if (e.found) {
      const Eigen::Vector2d direction = (piece.image.b - piece.image.a).normalized();
      for (const Segment2& s : along) {
        evaluation.offsets_px.push_back(std::abs(Cross2(direction, s.a - piece.image.a)));
        evaluation.offsets_px.push_back(std::abs(Cross2(direction, s.b - piece.image.a)));
        evaluation.angle_errors_deg.push_back(RadToDeg(LineAngle(piece.image, s)));
      }
      const Eigen::Vector2d ends[2] = {piece.image.a, piece.image.b};
      for (int k = 0; k < 2; ++k) {
        if (!observable.true_end[k]) continue;
        e.end_measured[k] = true;
        double best = std::numeric_limits<double>::infinity();
        for (const Segment2& s : along)
          best = std::min({best, (s.a - ends[k]).norm(), (s.b - ends[k]).norm()});
        e.endpoint_error[k] = best;
        evaluation.endpoint_errors.push_back(best);
      }
      ++evaluation.found;
    }
    evaluation.edges.push_back(std::move(e));
  }
  return evaluation;
}

std::vector<std::vector<int>> TrueCorrespondences(const std::vector<ProjectedEdge>& truth,
                                                  const std::vector<Segment2>& detections,
                                                  const DetectionMatchOptions& options) {
  std::vector<std::vector<int>> ids(detections.size());
  for (size_t i = 0; i < detections.size(); ++i) {
    for (const ProjectedEdge& piece : truth) {
      if (!DetectionOnEdge(piece.image, detections[i], options)) continue;
      if (std::find(ids[i].begin(), ids[i].end(), piece.edge_id) == ids[i].end()) {
        ids[i].push_back(piece.edge_id);
      }
    }
    std::sort(ids[i].begin(), ids[i].end());
  }
  return ids;
}

namespace {

constexpr double kSampleStepPx = 2.0;
constexpr double kContrastReachPx = 2.0;  // intensities compared at +- this across the edge
// Clutter hides an edge sample when it is nearer than the edge by this much (relative, metres).
constexpr double kOccluderRelative = 0.02;
constexpr double kOccluderAbsoluteM = 0.03;

double Bilinear(const vpImage<unsigned char>& image, const Eigen::Vector2d& p) {
  const double x = std::clamp(p.x(), 0.0, image.getWidth() - 1.001);
  const double y = std::clamp(p.y(), 0.0, image.getHeight() - 1.001);
  const int u = static_cast<int>(x), v = static_cast<int>(y);
  const double a = x - u, b = y - v;
  auto at = [&](int c, int r) { return static_cast<double>(image[r][c]); };
  return (1 - a) * (1 - b) * at(u, v) + a * (1 - b) * at(u + 1, v) + (1 - a) * b * at(u, v + 1) +
         a * b * at(u + 1, v + 1);
}

}  // namespace

std::vector<ObservablePiece> ObservablePieces(const std::vector<ProjectedEdge>& edges,
                                              const vpImage<unsigned char>& clean,
                                              const SurfaceMap& surfaces, const RenderScene& scene,
                                              const CameraIntrinsics& camera,
                                              const Eigen::Isometry3d& cam_from_world,
                                              double min_contrast) {
  std::vector<ObservablePiece> pieces;
  for (const ProjectedEdge& edge : edges) {
    const double length = edge.image.Length();
    if (length <= 0.0) continue;
    const Eigen::Vector2d direction = (edge.image.b - edge.image.a) / length;
    const Eigen::Vector2d normal(-direction.y(), direction.x());
    // Depth along the edge: 1/z is affine in the image parameter (perspective).
    const double za = (cam_from_world * edge.world.a).z(), zb = (cam_from_world * edge.world.b).z();
    const int n = std::max(1, static_cast<int>(length / kSampleStepPx));
    std::vector<bool> good(n + 1, false);
    for (int k = 0; k <= n; ++k) {
      const double s = static_cast<double>(k) / n;
      const Eigen::Vector2d p = edge.image.a + s * (edge.image.b - edge.image.a);
      const int u = static_cast<int>(std::lround(p.x())), v = static_cast<int>(std::lround(p.y()));
      if (u < 0 || v < 0 || u >= surfaces.width || v >= surfaces.height) continue;
      const double z = 1.0 / ((1.0 - s) / za + s / zb);
      const int id = surfaces.At(u, v);
      if (id >= 0 && scene.surfaces[id].kind == SurfaceKind::kClutter &&
          surfaces.DepthAt(u, v) < z * (1.0 - kOccluderRelative) - kOccluderAbsoluteM) {
        continue;
      }
      const double left = Bilinear(clean, DistortedPixelOf(camera, p + kContrastReachPx * normal));
      const double right = Bilinear(clean, DistortedPixelOf(camera, p - kContrastReachPx * normal));
      good[k] = std::abs(left - right) >= min_contrast;
    }
    // Runs of good samples, single bad samples bridged.
    int k = 0;
    while (k <= n) {
      if (!good[k]) {
        ++k;
        continue;
      }
      int last = k;
      while (last + 1 <= n && (good[last + 1] || (last + 2 <= n && good[last + 2]))) {
        last += good[last + 1] ? 1 : 2;
      }
      if (last > k) {
        ObservablePiece piece;
        piece.edge = edge;
        const double s0 = static_cast<double>(k) / n, s1 = static_cast<double>(last) / n;
        piece.edge.image = {edge.image.a + s0 * (edge.image.b - edge.image.a),
                            edge.image.a + s1 * (edge.image.b - edge.image.a)};
        piece.true_end[0] = k == 0;
        piece.true_end[1] = last == n;
        pieces.push_back(piece);
      }
      k = last + 1;
    }
  }
  return pieces;
}

}  // namespace linetrack

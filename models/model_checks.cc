#include "models/model_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "models/convex_polygon.h"
#include "models/errors.h"
#include "models/free_space.h"
#include "models/text_format.h"

namespace linetrack {
namespace {

// Points along a 3D line tested against the faces.
constexpr int kLineSamples = 5;
// Open wall ends listed in a finding at most.
constexpr size_t kMaxListed = 3;

double DistanceToSegment3(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + t * d - p).norm();
}

// The polygon of a face in the plane of its two non-dominant axes.
Ring2 Projected(const ModelFace& face) {
  int drop = 0;
  face.normal.cwiseAbs().maxCoeff(&drop);
  Ring2 ring;
  for (const Eigen::Vector3d& c : face.corners)
    ring.emplace_back(c[(drop + 1) % 3], c[(drop + 2) % 3]);
  return ring;
}

bool SegmentsMeet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  const Eigen::Vector2d& d) {
  const double d1 = Cross2(b - a, c - a), d2 = Cross2(b - a, d - a);
  const double d3 = Cross2(d - c, a - c), d4 = Cross2(d - c, b - c);
  if (((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 &&
      d4 != 0) {
    return true;
  }
  // Touching: an end on the other segment.
  auto on = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return std::abs(Cross2(q - p, r - p)) <= 1e-12 * (q - p).squaredNorm() &&
           (r - p).dot(r - q) <= 0.0;
  };
  return on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b);
}

// A face's bounding box, to skip faces far from a point.
struct FaceBox {
  const ModelFace* face = nullptr;
  Eigen::Vector3d lo, hi;
};

// 3D lines on no face: the largest distance of their sample points to the nearest face.
void CheckLines(const WireframeModel& model, const ModelCheckOptions& options,
                std::vector<ModelFinding>* findings) {
  std::vector<FaceBox> boxes;
  for (const ModelFace& face : model.faces()) {
    if (face.Degenerate()) continue;
    FaceBox box{&face, face.corners.front(), face.corners.front()};
    for (const Eigen::Vector3d& c : face.corners)
      box.lo = box.lo.cwiseMin(c), box.hi = box.hi.cwiseMax(c);
    boxes.push_back(box);
  }
  for (const ModelEdge& edge : model.edges()) {
    if (!edge.from_line) continue;
    double worst = 0.0;
    for (int k = 0; k < kLineSamples; ++k) {
      const Eigen::Vector3d p =
          edge.segment.a + (k / (kLineSamples - 1.0)) * (edge.segment.b - edge.segment.a);
      double nearest = std::numeric_limits<double>::infinity();
      for (const FaceBox& box : boxes) {
        // The distance to the box bounds the distance to the face from below.
        const double to_box =
            (box.lo - p).cwiseMax(p - box.hi).cwiseMax(Eigen::Vector3d::Zero()).norm();
        if (to_box >= nearest) continue;
        nearest = std::min(nearest, DistanceToFace(*box.face, p));
        if (nearest <= options.on_face_tolerance) break;
      }
      worst = std::max(worst, nearest);
    }
    if (worst <= options.on_face_tolerance) continue;
    const std::string where =
        std::isfinite(worst) ? Fixed(worst) + " m from the nearest face" : "the model has no face";
    findings->push_back(
        {FindingKind::kStrayLine,
         Located(model.path(), 0,
                 "3D line (edge " + std::to_string(edge.id) + ") lies on no face (" + where +
                     "): door and window frames belong on their wall, or they are matched "
                     "where no image line can be")});
  }
}

void CheckFaces(const WireframeModel& model, const ModelCheckOptions& options,
                std::vector<ModelFinding>* findings) {
  std::vector<int> degenerate, non_planar, crossing;
  for (size_t f = 0; f < model.faces().size(); ++f) {
    const ModelFace& face = model.faces()[f];
    if (face.Degenerate()) {
      degenerate.push_back(static_cast<int>(f));
      continue;
    }
    double off = 0.0;
    for (const Eigen::Vector3d& c : face.corners)
      off = std::max(off, std::abs(face.normal.dot(c) - face.offset));
    if (off > options.planar_tolerance) non_planar.push_back(static_cast<int>(f));
    if (SelfIntersecting(face)) crossing.push_back(static_cast<int>(f));
  }
  auto list = [](const std::vector<int>& ids) {
    std::string out;
    for (size_t i = 0; i < ids.size() && i < kMaxListed; ++i)
      out += (i > 0 ? ", " : "") + std::to_string(ids[i]);
    return out + (ids.size() > kMaxListed ? ", ..." : "");
  };
  if (!degenerate.empty()) {
    findings->push_back(
        {FindingKind::kDegenerateFace,
         Located(model.path(), 0,
                 std::to_string(degenerate.size()) + " faces without area (faces " +
                     list(degenerate) + "): they neither occlude nor bound a space")});
  }
  if (!non_planar.empty()) {
    findings->push_back(
        {FindingKind::kNonPlanarFace,
         Located(model.path(), 0,
                 std::to_string(non_planar.size()) + " faces are not planar (faces " +
                     list(non_planar) + "): occlusion and orientation use a plane through them")});
  }
  if (!crossing.empty()) {
    findings->push_back(
        {FindingKind::kSelfIntersectingFace,
         Located(model.path(), 0,
                 std::to_string(crossing.size()) + " faces intersect themselves (faces " +
                     list(crossing) + "): their inside is undefined")});
  }
}

// Enclosure: free space somewhere, and no wall end open to the outside.
void CheckEnclosure(const WireframeModel& model, std::vector<ModelFinding>* findings) {
  if (!model.oriented()) {
    findings->push_back(
        {FindingKind::kNoFreeSpace,
         Located(model.path(), 0,
                 "no face encloses a free space (no room with walls all round): the navigable "
                 "area falls back to the bounding box + 2 m and faces keep the file's order")});
  }
  FreeSpace space(model);
  for (size_t s = 0; s < model.storeys().size(); ++s) {
    const PlanSection& nav = space.SectionAt(NavigationHeight(model.storeys()[s], space.options()));
    const PlanArrangement& arr = nav.arrangement();
    std::vector<Eigen::Vector2d> open;
    for (const PlanCycle& cycle : arr.cycles()) {
      if (cycle.signed_area > 1e-6 || nav.EnclosingCell(cycle.component) >= 0) continue;
      for (int v : cycle.vertices) {
        if (arr.Neighbours(v).size() == 1) open.push_back(arr.vertices()[v]);
      }
    }
    if (open.empty()) continue;
    std::string where;
    for (size_t i = 0; i < open.size() && i < kMaxListed; ++i)
      where += (i > 0 ? ", (" : "(") + Fixed(open[i].x()) + ", " + Fixed(open[i].y()) + ")";
    findings->push_back(
        {FindingKind::kOpenWalls,
         Located(model.path(), 0,
                 "storey " + std::to_string(s) + ": the walls leave a gap: " +
                     std::to_string(open.size()) + " wall ends open to the outside at " + where +
                     (open.size() > kMaxListed ? ", ..." : "") +
                     "; a space they leave open is not navigable (a missing wall?)")});
  }
}

void CheckScale(const WireframeModel& model, const ModelCheckOptions& options,
                std::vector<ModelFinding>* findings) {
  if (model.vertices().empty()) return;
  const Eigen::Vector3d extent = model.BoxMax() - model.BoxMin();
  if (extent.maxCoeff() > options.max_extent) {
    findings->push_back({FindingKind::kImplausibleExtent,
                         Located(model.path(), 0,
                                 "the model is " + Fixed(extent.maxCoeff(), 0) +
                                     " m wide: is it in millimetres? linetrack reads metres")});
  }
  const Eigen::Vector3d centre = 0.5 * (model.BoxMin() + model.BoxMax());
  if (centre.norm() > options.max_origin_distance) {
    findings->push_back(
        {FindingKind::kFarFromOrigin,
         Located(model.path(), 0,
                 "the model lies " + Fixed(centre.norm(), 0) +
                     " m from the origin (georeferenced?): poses lose precision; move it near "
                     "the origin")});
  }
  const double shortest = options.min_image_length_px * options.viewing_distance / options.focal_px;
  int short_edges = 0;
  for (const ModelEdge& edge : model.edges())
    short_edges += edge.segment.Length() < shortest ? 1 : 0;
  if (short_edges > 0) {
    findings->push_back(
        {FindingKind::kShortEdges,
         Located(model.path(), 0,
                 std::to_string(short_edges) + " of " + std::to_string(model.edges().size()) +
                     " edges are shorter than " + Fixed(100.0 * shortest, 1) + " cm: seen from " +
                     Fixed(options.viewing_distance, 1) +
                     " m with f = " + Fixed(options.focal_px, 0) + " px their images are under " +
                     Fixed(options.min_image_length_px, 0) + " px, too short for the matcher")});
  }
}

}  // namespace

bool ModelCheckOptions::Check(std::string* why) const {
  if (!(on_face_tolerance > 0.0 && planar_tolerance > 0.0 && max_extent > 0.0 &&
        max_origin_distance > 0.0 && focal_px > 0.0 && viewing_distance > 0.0 &&
        min_image_length_px >= 0.0)) {
    *why = "model checks: tolerances, extents, focal length and distance must be > 0";
    return false;
  }
  return true;
}

double DistanceToFace(const ModelFace& face, const Eigen::Vector3d& p) {
  const double height = face.normal.dot(p) - face.offset;
  const Eigen::Vector3d q = p - height * face.normal;
  int drop = 0;
  face.normal.cwiseAbs().maxCoeff(&drop);
  if (RingContains(Projected(face), {q[(drop + 1) % 3], q[(drop + 2) % 3]})) {
    return std::abs(height);
  }
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < face.corners.size(); ++i) {
    best = std::min(
        best, DistanceToSegment3(p, face.corners[i], face.corners[(i + 1) % face.corners.size()]));
  }
  return best;
}

bool SelfIntersecting(const ModelFace& face) {
  const Ring2 ring = Projected(face);
  const size_t n = ring.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing side
      if (SegmentsMeet(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n])) return true;
    }
  }
  return false;
}

std::vector<ModelFinding> CheckModel(const WireframeModel& model,
                                     const ModelCheckOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path(), 0, why));
  std::vector<ModelFinding> findings;
  if (!model.edges().empty() && model.NumVerticalEdges() == 0) {
    findings.push_back({FindingKind::kNoVerticalEdges,
                        Located(model.path(), 0,
                                "no vertical edges: the matcher's first stage pairs vertical "
                                "edges with image lines, and finds nothing without them")});
  }
  CheckEnclosure(model, &findings);
  CheckLines(model, options, &findings);
  CheckFaces(model, options, &findings);
  CheckScale(model, options, &findings);
  return findings;
}

}  // namespace linetrack

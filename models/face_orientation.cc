#include "models/face_orientation.h"

#include <algorithm>
#include <cmath>

#include "models/convex_polygon.h"
#include "models/occlusion.h"
#include "models/plan_visibility.h"

namespace linetrack {
namespace {

// A section keeps the parts of faces covering [z - kBand, z + kBand]; sample heights stay this far
// inside a face's height range (metres).
constexpr double kBand = 1e-4;
constexpr double kEdgeMargin = 0.01;
// Spans shorter than this give no sample (metres); at most this many convex pieces are sampled.
constexpr double kMinSpan = 0.01;
constexpr size_t kMaxPieces = 4;
// Cameras deciding by sight stand below the ceiling by at least this (metres).
constexpr double kBelowCeiling = 0.1;

// Free space beats outside, outside beats solid: a face looks at the best of its two sides.
int Rank(SpaceKind kind) {
  switch (kind) {
    case SpaceKind::kFree:
      return 2;
    case SpaceKind::kOutside:
      return 1;
    case SpaceKind::kSolid:
      return 0;
  }
  return 0;
}

// Sample points of a vertical face at one height: a quarter, half and three quarters along each
// span of the face at the first of a few storey heights it covers (the navigation section first,
// which the navigable area uses too); empty when it covers none.
std::vector<Eigen::Vector3d> VerticalSamples(const ModelFace& face,
                                             const std::vector<Storey>& storeys,
                                             const FreeSpaceOptions& options) {
  const WallInPlane wall = ToWallPlane(face);
  const double z_lo = wall.z_lo, z_hi = wall.z_hi;
  const Storey& st = storeys[StoreyAt(storeys, 0.5 * (z_lo + z_hi))];
  std::vector<Eigen::Vector3d> points;
  for (double z : {NavigationHeight(st, options), st.floor_z + 1.0, 0.5 * (st.floor_z + st.top_z),
                   st.top_z - 0.25, 0.5 * (z_lo + z_hi)}) {
    if (z < z_lo + kEdgeMargin || z > z_hi - kEdgeMargin) continue;
    for (const auto& [s0, s1] : FullHeightSpans(wall.s_z, z - kBand, z + kBand)) {
      if (s1 - s0 < kMinSpan) continue;
      for (double f : {0.25, 0.5, 0.75}) {
        const Eigen::Vector2d p = wall.At(s0 + f * (s1 - s0));
        points.emplace_back(p.x(), p.y(), z);
      }
    }
    if (!points.empty()) break;
  }
  return points;
}

// Sample points of any face: the centroids of the largest convex pieces of its polygon.
std::vector<Eigen::Vector3d> PlanarSamples(const ModelFace& face) {
  int drop = 0;
  face.normal.cwiseAbs().maxCoeff(&drop);
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  Ring2 ring;
  for (const Eigen::Vector3d& c : face.corners)
    ring.emplace_back(c[u], c[v]);
  if (RingSignedArea(ring) < 0.0) std::reverse(ring.begin(), ring.end());
  std::vector<Ring2> pieces = ConvexPieces(SimplifyRing(ring, 1e-9));
  std::sort(pieces.begin(), pieces.end(),
            [](const Ring2& a, const Ring2& b) { return RingSignedArea(a) > RingSignedArea(b); });
  if (pieces.size() > kMaxPieces) pieces.resize(kMaxPieces);
  std::vector<Eigen::Vector2d> centres;
  for (const Ring2& piece : pieces)
    centres.push_back(RingCentroid(piece));
  if (centres.empty()) centres.push_back(RingCentroid(ring));
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector2d& c : centres) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p[u] = c.x();
    p[v] = c.y();
    p[drop] = (face.offset - face.normal[u] * c.x() - face.normal[v] * c.y()) / face.normal[drop];
    points.push_back(p);
  }
  return points;
}

struct ViewCounts {
  int front = 0, back = 0;
};

// Camera positions of the free space near the samples (the storey's navigation section, away
// from walls) at several heights, counted by the side of the face they see a sample from.
ViewCounts CountViews(const ModelFace& face, const std::vector<Eigen::Vector3d>& samples,
                      const WireframeModel& model, FreeSpace* space,
                      const OcclusionTester& occlusion, const FaceOrientationOptions& options) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& q : samples)
    mean += q / static_cast<double>(samples.size());
  const Storey& storey = model.storeys()[StoreyAt(model.storeys(), mean.z())];
  const PlanSection& nav = space->SectionAt(NavigationHeight(storey, options.space));
  const double range = options.view_range, pitch = options.view_pitch;
  const int steps = static_cast<int>(std::ceil(2.0 * range / pitch));
  ViewCounts counts;
  for (int j = 0; j < steps; ++j) {
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector2d p =
          mean.head<2>() + Eigen::Vector2d(-range + (i + 0.5) * pitch, -range + (j + 0.5) * pitch);
      if ((p - mean.head<2>()).norm() > range || nav.Classify(p).kind != SpaceKind::kFree) continue;
      const bool near_wall = std::any_of(
          nav.walls().begin(), nav.walls().end(),
          [&](const auto& w) { return DistanceToSegment(p, w) < options.view_clearance; });
      if (near_wall) continue;
      for (double h = storey.floor_z + 0.5; h < storey.top_z - kBelowCeiling; h += 0.5) {
        const Eigen::Vector3d eye(p.x(), p.y(), h);
        for (const Eigen::Vector3d& q : samples) {
          const double side = (eye - q).dot(face.normal);
          if (std::abs(side) < 1e-9 || occlusion.Blocked(eye, q)) continue;
          (side > 0.0 ? counts.front : counts.back) += 1;
        }
      }
    }
  }
  return counts;
}

// Compares the two sides of the face at every sample. Samples with free space on one side only
// vote for it; only when there are none do samples between outside and a solid vote (a facade):
// a room's wall with a cabinet against it has solid in front of it there and outside behind, but
// free space in front elsewhere. Ties between two free sides are left to CountViews.
FaceOrientation DecideBySpace(const ModelFace& face, const std::vector<Eigen::Vector3d>& samples,
                              FreeSpace* space, double offset, int* both_free) {
  int free_vote = 0, outer_vote = 0;
  SpaceAt free_front, free_back, outer_front, outer_back;  // what lies behind the winning side
  for (const Eigen::Vector3d& q : samples) {
    const SpaceAt front = space->Classify(q + offset * face.normal);
    const SpaceAt back = space->Classify(q - offset * face.normal);
    const int rf = Rank(front.kind), rb = Rank(back.kind);
    const bool free_side = front.kind == SpaceKind::kFree || back.kind == SpaceKind::kFree;
    int* vote = free_side ? &free_vote : &outer_vote;
    if (rf > rb) {
      ++*vote;
      (free_side ? free_front : outer_front) = back;
    } else if (rb > rf) {
      --*vote;
      (free_side ? free_back : outer_back) = front;
    } else if (front.kind == SpaceKind::kFree) {
      ++*both_free;
    }
  }
  FaceOrientation decision;
  decision.rule = OrientationRule::kUndecided;
  const int vote = free_vote != 0 ? free_vote : outer_vote;
  if (vote == 0) return decision;
  decision.flip = vote < 0;
  if (free_vote != 0) {
    decision.rule = OrientationRule::kFreeSide;
    decision.behind = decision.flip ? free_back : free_front;
  } else {
    decision.rule = OrientationRule::kOutsideSide;
    decision.behind = decision.flip ? outer_back : outer_front;
  }
  return decision;
}

std::string Counted(int n, const std::string& singular, const std::string& plural,
                    const std::string& rest) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural) + " " + rest;
}

}  // namespace

std::vector<FaceOrientation> OrientFaces(const WireframeModel& model,
                                         const FaceOrientationOptions& options) {
  FreeSpace space(model, options.space);
  std::vector<FaceOrientation> out;
  const bool encloses =
      std::any_of(model.storeys().begin(), model.storeys().end(), [&](const Storey& storey) {
        const PlanSection& nav = space.SectionAt(NavigationHeight(storey, options.space));
        return std::any_of(nav.cells().begin(), nav.cells().end(),
                           [](const SectionCell& cell) { return cell.kind == SpaceKind::kFree; });
      });
  if (!encloses) return out;
  std::unique_ptr<OcclusionTester> occlusion;
  for (const ModelFace& face : model.faces()) {
    if (face.Degenerate()) {
      out.emplace_back();
      continue;
    }
    std::vector<Eigen::Vector3d> samples;
    if (face.vertical) {
      samples = VerticalSamples(face, model.storeys(), options.space);
    }
    if (samples.empty()) samples = PlanarSamples(face);
    int both_free = 0;
    FaceOrientation decision =
        DecideBySpace(face, samples, &space, options.side_offset, &both_free);
    if (decision.rule == OrientationRule::kUndecided && both_free > 0) {
      if (!occlusion) occlusion = std::make_unique<OcclusionTester>(model);
      const ViewCounts views = CountViews(face, samples, model, &space, *occlusion, options);
      const int most = std::max(views.front, views.back);
      const int least = std::min(views.front, views.back);
      if (most > 0 && least >= options.two_sided_share * most) {
        decision.rule = OrientationRule::kTwoSided;
      } else if (most > 0) {
        decision.rule = OrientationRule::kSeenSide;
        decision.flip = views.back > views.front;
      }
    }
    out.push_back(decision);
  }
  return out;
}

std::vector<std::string> OrientationSummary(const WireframeModel& model,
                                            const std::vector<FaceOrientation>& orientation) {
  int walls = 0, obstacles = 0, floors = 0, ceilings = 0, sloped = 0, outer = 0, seen = 0,
      two_sided = 0, undecided = 0;
  for (size_t f = 0; f < orientation.size() && f < model.faces().size(); ++f) {
    const FaceOrientation& o = orientation[f];
    const ModelFace& face = model.faces()[f];
    two_sided += o.rule == OrientationRule::kTwoSided ? 1 : 0;
    undecided += o.rule == OrientationRule::kUndecided ? 1 : 0;
    if (!o.flip) continue;
    if (o.rule == OrientationRule::kOutsideSide) {
      ++outer;
    } else if (o.rule == OrientationRule::kSeenSide) {
      ++seen;
    } else if (o.behind.solid_reason == SolidReason::kNested ||
               o.behind.solid_reason == SolidReason::kTopped) {
      ++obstacles;
    } else if (face.vertical) {
      ++walls;
    } else if (face.horizontal) {
      // `face` holds the oriented normal when the model applied the decision.
      (face.normal.z() > 0.0 ? floors : ceilings) += 1;
    } else {
      ++sloped;
    }
  }
  std::vector<std::string> out;
  auto add = [&](int n, const std::string& singular, const std::string& plural,
                 const std::string& rest) {
    if (n > 0) out.push_back(Counted(n, singular, plural, rest));
  };
  add(walls, "wall face", "wall faces", "turned to face the room");
  add(obstacles, "obstacle face", "obstacle faces", "turned outward");
  add(floors, "floor face", "floor faces", "turned up");
  add(ceilings, "ceiling face", "ceiling faces", "turned down");
  add(sloped, "sloped face", "sloped faces", "turned to the free space");
  add(outer, "outer face", "outer faces", "turned outward");
  add(seen, "face", "faces", "turned to the side the free space sees");
  add(two_sided, "face", "faces",
      "with free space on both sides, seen from both (the tracker gets both sides)");
  add(undecided, "face", "faces",
      "with no free space on either side, or seen from neither, kept as written");
  return out;
}

}  // namespace linetrack

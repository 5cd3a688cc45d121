#include "matching/views/view_positioning.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "models/errors.h"

namespace linetrack {

bool ViewPositioningOptions::Check(std::string* why) const {
  if (!retrieval.Check(why)) return false;
  if (merged_views < 1 || min_points < 4 || ransac_iterations < 1 || !(inlier_px > 0.0) ||
      !(min_heading_change_deg >= 0.0) || !(min_baseline_m >= 0.0) ||
      !(min_junction_angle_deg >= 0.0) || !(max_baseline_m > min_baseline_m) ||
      !(max_scale_mismatch > 0.0) || !(max_orthogonality > 0.0) || !(max_roll_deg > 0.0) ||
      !(max_tilt_change_deg > 0.0) || !(max_height_change_m > 0.0)) {
    *why =
        "view positioning options: merged_views >= 1, min_points >= 4, ransac_iterations >= 1, "
        "positive thresholds, min_baseline_m < max_baseline_m";
    return false;
  }
  return true;
}

std::optional<Eigen::Vector2d> LineIntersection(const Segment2& a, const Segment2& b,
                                                double min_angle) {
  const Eigen::Vector2d da = (a.b - a.a).normalized(), db = (b.b - b.a).normalized();
  const double sine = std::abs(Cross2(da, db));
  if (sine < std::sin(min_angle)) return std::nullopt;
  const double t = Cross2(b.a - a.a, db) / Cross2(da, db);
  return a.a + t * da;
}

namespace {

// Image segment given each line id by the first retrieved views, every token of them matched
// again (retrieval matches only the longest); the best ratio, each segment once.
std::map<int, int> ImageLineOfId(const std::vector<Segment2>& lines, const ViewDatabase& db,
                                 const std::vector<RetrievedView>& ranked,
                                 const ViewPositioningOptions& options) {
  RetrievalOptions every_token = options.retrieval;
  every_token.max_view_tokens = std::numeric_limits<int>::max();
  const std::vector<Token> image_tokens = ImageTokens(lines, db);
  std::vector<TransferredPair> pairs;
  for (int r = 0; r < std::min<int>(options.merged_views, ranked.size()); ++r) {
    for (const TransferredPair& p :
         MatchView(image_tokens, db, ranked[r].view, every_token).pairs) {
      if (p.line_id >= 0) pairs.push_back(p);
    }
  }
  std::stable_sort(
      pairs.begin(), pairs.end(),
      [](const TransferredPair& a, const TransferredPair& b) { return a.llr > b.llr; });
  std::map<int, int> out;
  std::map<int, bool> line_used;
  for (const TransferredPair& p : pairs) {
    if (out.count(p.line_id) || line_used[p.line]) continue;
    out[p.line_id] = p.line;
    line_used[p.line] = true;
  }
  return out;
}

// The image points of view 1's junctions whose two lines both have an image segment.
std::map<int, Eigen::Vector2d> ImageJunctions(const std::vector<Segment2>& lines,
                                              const std::map<int, int>& line_of_id,
                                              const KeyView& view1, double min_angle) {
  std::map<int, Eigen::Vector2d> out;
  for (const ViewJunction& j : view1.junctions) {
    std::vector<int> seen;  // image segments of the junction's lines
    for (int id : j.lines) {
      const auto it = line_of_id.find(id);
      if (it != line_of_id.end()) seen.push_back(it->second);
    }
    // The two lines meeting at the widest angle.
    double widest = 0.0;
    for (size_t a = 0; a < seen.size(); ++a) {
      for (size_t b = a + 1; b < seen.size(); ++b) {
        const Segment2 &sa = lines[seen[a]], &sb = lines[seen[b]];
        const double sine =
            std::abs(Cross2((sa.b - sa.a).normalized(), (sb.b - sb.a).normalized()));
        const auto point = LineIntersection(sa, sb, min_angle);
        if (!point || sine <= widest) continue;
        widest = sine;
        out[j.point_id] = *point;
      }
    }
  }
  return out;
}

std::map<int, Eigen::Vector2d> JunctionPixels(const KeyView& view) {
  std::map<int, Eigen::Vector2d> out;
  for (const ViewJunction& j : view.junctions)
    out[j.point_id] = j.pixel;
  return out;
}

// The view sharing most image points with view 1's (the nearest of those), its heading and
// position far enough away, its position near enough.
int SecondView(const ViewDatabase& db, int view1, const std::map<int, Eigen::Vector2d>& points,
               const ViewPositioningOptions& options) {
  int best = -1, best_count = 0;
  double best_baseline = 0.0;
  const RobotPose& p1 = db.views[view1].pose;
  for (size_t v = 0; v < db.views.size(); ++v) {
    const RobotPose& p = db.views[v].pose;
    const double baseline = std::hypot(p.x - p1.x, p.y - p1.y);
    if (std::abs(WrapAngle(p.heading - p1.heading)) < DegToRad(options.min_heading_change_deg) ||
        baseline < options.min_baseline_m || baseline > options.max_baseline_m) {
      continue;
    }
    int count = 0;
    for (const ViewJunction& j : db.views[v].junctions)
      count += points.count(j.point_id);
    if (count > best_count || (count == best_count && count > 0 && baseline < best_baseline)) {
      best_count = count;
      best = static_cast<int>(v);
      best_baseline = baseline;
    }
  }
  return best;
}

Eigen::Vector2d Normalised(const CameraIntrinsics& c, const Eigen::Vector2d& uv) {
  return {(uv.x() - c.u0) / c.px, (uv.y() - c.v0) / c.py};
}

// Correspondences of three views, in normalised coordinates.
struct Triplets {
  std::vector<Eigen::Vector2d> view1, view2, novel;
};

struct CombinationFit {
  ViewCombination combination;
  std::vector<int> inliers;
};

std::vector<int> Inliers(const Triplets& t, const ViewCombination& c, double threshold) {
  std::vector<int> out;
  for (size_t i = 0; i < t.novel.size(); ++i) {
    const Eigen::Vector4d basis(t.view1[i].x(), t.view1[i].y(), t.view2[i].x(), 1.0);
    const Eigen::Vector2d predicted(c.a.dot(basis), c.b.dot(basis));
    if ((predicted - t.novel[i]).norm() <= threshold) out.push_back(static_cast<int>(i));
  }
  return out;
}

std::optional<ViewCombination> FitSubset(const Triplets& t, const std::vector<int>& subset) {
  std::vector<Eigen::Vector2d> v1, n;
  std::vector<double> x2;
  for (int i : subset) {
    v1.push_back(t.view1[i]);
    x2.push_back(t.view2[i].x());
    n.push_back(t.novel[i]);
  }
  return FitViewCombination(v1, x2, n);
}

// RANSAC on minimal sets of four points, then least squares on the largest consensus (with
// exactly four points, their exact fit).
std::optional<CombinationFit> RobustCombination(const Triplets& t, double threshold,
                                                const ViewPositioningOptions& options) {
  const int n = static_cast<int>(t.novel.size());
  if (n < std::max(4, options.min_points)) return std::nullopt;
  if (n == 4) {
    const auto exact = FitSubset(t, {0, 1, 2, 3});
    if (!exact) return std::nullopt;
    return CombinationFit{*exact, {0, 1, 2, 3}};
  }
  std::mt19937_64 rng(options.seed);
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i)
    all[i] = i;
  std::optional<CombinationFit> best;
  for (int it = 0; it < options.ransac_iterations; ++it) {
    std::vector<int> sample = all;
    for (int k = 0; k < 4; ++k) {
      std::uniform_int_distribution<int> pick(k, n - 1);
      std::swap(sample[k], sample[pick(rng)]);
    }
    sample.resize(4);
    const auto c = FitSubset(t, sample);
    if (!c) continue;
    std::vector<int> inliers = Inliers(t, *c, threshold);
    if (!best || inliers.size() > best->inliers.size()) best = CombinationFit{*c, inliers};
  }
  if (!best || static_cast<int>(best->inliers.size()) < options.min_points) return std::nullopt;
  const auto refit = FitSubset(t, best->inliers);
  if (!refit) return std::nullopt;
  return CombinationFit{*refit, Inliers(t, *refit, threshold)};
}

// Camera-2-from-camera-1 rotation and camera 2's centre in camera 1's frame.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> RelativePose(const RobotPose& p1, const RobotPose& p2) {
  const Eigen::Isometry3d c1 = CamFromWorld(p1), c2 = CamFromWorld(p2);
  return {c2.linear() * c1.linear().transpose(), c1 * p2.Centre()};
}

// The junctions the two model views share (normalised), and those of them also seen in the
// image as triplets.
struct SharedJunctions {
  std::vector<Eigen::Vector2d> view1, view2;
  Triplets triplets;
};

SharedJunctions Shared(const ViewDatabase& db, const KeyView& view1, const KeyView& view2,
                       const std::map<int, Eigen::Vector2d>& image_points) {
  SharedJunctions out;
  const std::map<int, Eigen::Vector2d> pixels2 = JunctionPixels(view2);
  for (const auto& [id, px1] : JunctionPixels(view1)) {
    const auto px2 = pixels2.find(id);
    if (px2 == pixels2.end()) continue;
    out.view1.push_back(Normalised(db.camera, px1));
    out.view2.push_back(Normalised(db.camera, px2->second));
    const auto seen = image_points.find(id);
    if (seen == image_points.end()) continue;
    out.triplets.view1.push_back(out.view1.back());
    out.triplets.view2.push_back(out.view2.back());
    out.triplets.novel.push_back(Normalised(db.camera, seen->second));
  }
  return out;
}

// The world pose of the novel view (camera-from-world = U * camera1-from-world, centre = C1 +
// R1^T c_n) and its checks.
void SetPose(const NovelView& novel, const KeyView& view1, const ViewPositioningOptions& options,
             ViewPositioning* out) {
  const Eigen::Isometry3d c1 = CamFromWorld(view1.pose);
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  cam_from_world.linear() = novel.rotation * c1.linear();
  const Eigen::Vector3d world_centre = c1.inverse() * novel.centre;
  cam_from_world.translation() = -cam_from_world.linear() * world_centre;
  out->pose = RobotPoseFromCamFromWorld(cam_from_world);
  out->roll = RollOf(cam_from_world);
  out->scale_a = novel.scale_a;
  out->scale_b = novel.scale_b;
  out->orthogonality = novel.orthogonality;
  const double scale = 0.5 * (novel.scale_a + novel.scale_b);
  out->weak_perspective_ok =
      std::abs(novel.scale_a - novel.scale_b) / scale <= options.max_scale_mismatch &&
      std::abs(novel.orthogonality) <= options.max_orthogonality;
  out->plausible =
      std::abs(out->roll) <= DegToRad(options.max_roll_deg) &&
      std::abs(out->pose.tilt - view1.pose.tilt) <= DegToRad(options.max_tilt_change_deg) &&
      std::abs(out->pose.height - view1.pose.height) <= options.max_height_change_m;
}

}  // namespace

ViewPositioning LocalizeFromViews(const std::vector<Segment2>& lines, const ViewDatabase& db,
                                  const ViewPositioningOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(why);
  ViewPositioning out;
  const std::vector<RetrievedView> ranked = RetrieveViews(lines, db, options.retrieval);
  if (ranked.empty()) {
    out.reason = "no stored view matches the image's tokens";
    return out;
  }
  out.view1 = ranked.front().view;
  const KeyView& view1 = db.views[out.view1];
  const std::map<int, Eigen::Vector2d> image_points =
      ImageJunctions(lines, ImageLineOfId(lines, db, ranked, options), view1,
                     DegToRad(options.min_junction_angle_deg));
  out.view2 = SecondView(db, out.view1, image_points, options);
  if (out.view2 < 0) {
    out.reason = "no second stored view shares the image's junctions";
    return out;
  }
  const KeyView& view2 = db.views[out.view2];
  const auto [rotation, centre] = RelativePose(view1.pose, view2.pose);
  const SharedJunctions shared = Shared(db, view1, view2, image_points);
  out.points = static_cast<int>(shared.triplets.novel.size());
  // Z0: the mean depth of every junction the two model views share.
  const auto z0 = MeanTriangulatedDepth(shared.view1, shared.view2, rotation, centre);
  const auto w2 = z0 ? WeakPerspectiveOf(rotation, centre, *z0) : std::nullopt;
  if (!w2) {
    out.reason = "the two stored views give no reference depth";
    return out;
  }
  out.reference_depth = *z0;
  const auto fit = RobustCombination(shared.triplets, options.inlier_px / db.camera.px, options);
  if (!fit) {
    out.reason = "fewer than " + std::to_string(options.min_points) +
                 " junctions agree on a combination of the two views";
    return out;
  }
  out.inliers = static_cast<int>(fit->inliers.size());
  out.rms_px = fit->combination.rms * db.camera.px;
  SetPose(RecoverNovelView(fit->combination, *w2, *z0), view1, options, &out);
  out.found = true;
  return out;
}

}  // namespace linetrack

// The report decision against rival lines (PairsBeatingRivalLines) on exact synthetic scenes of
// the hall: a line parallel to an edge's exact image at d pixels (a door casing's border, a box's
// bottom before a wall) contests the edge's pair within the noise and not beyond it, and a
// parallel line standing in for the edge's image, off where the other pairs put that image, is
// not reported though the pose was fit with it.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "matching/hypothesis_trimming.h"
#include "matching/pose_refinement.h"
#include "matching/reported_pairs.h"
#include "matching/verification.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {
namespace {

constexpr int kScenes = 8;
constexpr double kMinLinePx = 60.0;  // the contested line: long enough to be well measured
// Offsets of the parallel line, with the detected-line noise below (1 px, 0.3 deg): within the
// noise (both lines fit the edge nearly as well), and far beyond the gate (13.8 = 3.7 sigma).
constexpr double kWithinNoisePx = 1.5;
constexpr double kBeyondGatePx = 12.0;
// A parallel line standing in for the edge's image (the image itself not detected), this many
// standard deviations off where the other pairs put the edge's image (beyond the 3.7 of the
// gate: it fits only at a pose pulled toward it).
constexpr double kStandInSigmas = 7.0;

Segment2 Shifted(const Segment2& s, double offset_px) {
  const Eigen::Vector2d u = (s.b - s.a).normalized(), n(-u.y(), u.x());
  return {s.a + offset_px * n, s.b + offset_px * n};
}

bool Has(const std::vector<std::pair<int, int>>& pairs, std::pair<int, int> pair) {
  return std::find(pairs.begin(), pairs.end(), pair) != pairs.end();
}

class RivalLinesTest : public ::testing::Test {
 protected:
  RivalLinesTest()
      : model_(WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao")),
        area_(NavigableArea::FromModel(model_)),
        camera_(PaperSyntheticCamera().Undistorted()) {
    std::vector<int> ids(model_.edges().size());
    std::iota(ids.begin(), ids.end(), 0);
    edges_ = PrepareEdges(model_, ids);  // index = edge id
    noise_.offset_px = 1.0;              // DetectedLineNoise
    noise_.angle_deg = 0.3;
    noise_.focal_relative = 0.005;
    options_.refinement.focal_prior_sigma = noise_.focal_relative;
  }

  // Exact scenes (no noise, no clutter, no split lines).
  std::vector<SyntheticScene> Scenes() const {
    SyntheticSceneOptions options;
    options.seed = 31;
    options.count = kScenes;
    options.calibration_sigma = options.angle_sigma = options.offset_sigma_px = 0.0;
    options.min_clutter = options.max_clutter = 0;
    options.split_probability = 0.0;
    return GenerateScenes(model_, area_, options);
  }

  VerificationContext Context(const SyntheticScene& scene, const std::vector<Segment2>& lines) {
    lines_ = PrepareLines(lines, camera_, scene.tilt, noise_, 3.5);
    VerificationContext context;
    context.edges = &edges_;
    context.lines = &lines_;
    context.camera = &camera_;
    context.height = scene.height;
    context.tilt = scene.tilt;
    context.noise = noise_;
    return context;
  }

  // Of the pairs of the exact scene that are reported, with a line at least kMinLinePx long,
  // the one the other pairs pin down best (smallest position standard deviation without it):
  // its edge's image is known without its line. (-1, -1) when there is none.
  std::pair<int, int> PinnedReportedPair(const SyntheticScene& scene) {
    const VerificationContext context = Context(scene, scene.lines);
    std::pair<int, int> best = {-1, -1};
    double best_sigma = std::numeric_limits<double>::infinity();
    for (const auto& pair :
         PairsBeatingRivalLines(context, options_, Verified(context, scene, scene.matches))) {
      if (scene.lines[pair.second].Length() < kMinLinePx) continue;
      std::vector<std::pair<int, int>> others = scene.matches;
      const auto it = std::find(others.begin(), others.end(), pair);
      if (it == others.end()) continue;  // guided matching's pair, not one of the truth's
      others.erase(it);
      const double sigma = RefineHypothesis(context, others, {scene.truth.Planar()}, options_)
                               .refinement.position_sigma_m;
      if (sigma < best_sigma) {
        best_sigma = sigma;
        best = pair;
      }
    }
    return best;
  }

  // Verified from the truth with `pairs` (guided matching then assigns every line).
  VerifiedPose Verified(const VerificationContext& context, const SyntheticScene& scene,
                        const std::vector<std::pair<int, int>>& pairs) {
    return Rematch(context, RefineHypothesis(context, pairs, {scene.truth.Planar()}, options_),
                   options_);
  }

  // The pairs reported when line `line`, shifted by `offset_px`, is added to the scene's lines
  // (its index is scene.lines.size()).
  std::vector<std::pair<int, int>> ReportedWithParallelLine(const SyntheticScene& scene, int line,
                                                            double offset_px) {
    std::vector<Segment2> lines = scene.lines;
    lines.push_back(Shifted(lines[line], offset_px));
    const VerificationContext context = Context(scene, lines);
    return PairsBeatingRivalLines(context, options_, Verified(context, scene, scene.matches));
  }

  WireframeModel model_;
  NavigableArea area_;
  CameraIntrinsics camera_;
  std::vector<MatchEdge> edges_;
  std::vector<ObservedLine> lines_;
  LineNoise noise_;
  VerificationOptions options_;
};

TEST_F(RivalLinesTest, AParallelLineWithinTheNoiseContestsTheEdgeBeyondTheGateItDoesNot) {
  int tested = 0;
  for (const SyntheticScene& scene : Scenes()) {
    // A pair reported when the edge's exact image is alone.
    const auto [edge, line] = PinnedReportedPair(scene);
    if (edge < 0) continue;
    const int parallel = static_cast<int>(scene.lines.size());
    // A parallel line over the same stretch within the noise: neither line is the edge's image
    // with odds of e^report_nats; the other pairs are still reported.
    const std::vector<std::pair<int, int>> contested =
        ReportedWithParallelLine(scene, line, kWithinNoisePx);
    EXPECT_FALSE(Has(contested, {edge, line})) << "scene " << scene.index;
    EXPECT_FALSE(Has(contested, {edge, parallel})) << "scene " << scene.index;
    EXPECT_FALSE(contested.empty()) << "scene " << scene.index;
    // The same line far beyond the noise is no rival.
    const std::vector<std::pair<int, int>> uncontested =
        ReportedWithParallelLine(scene, line, kBeyondGatePx);
    EXPECT_TRUE(Has(uncontested, {edge, line})) << "scene " << scene.index;
    EXPECT_FALSE(Has(uncontested, {edge, parallel})) << "scene " << scene.index;
    ++tested;
  }
  EXPECT_GE(tested, kScenes / 2);
}

TEST_F(RivalLinesTest, AStandInForAnUndetectedImageIsNotReportedAtThePoseOfTheOthers) {
  int tested = 0;
  for (const SyntheticScene& scene : Scenes()) {
    const auto [edge, line] = PinnedReportedPair(scene);
    if (edge < 0) continue;
    // Where the other pairs put the edge's image: the standard deviation of the line's offset
    // at the segment's middle, from the pose without the pair (line noise included).
    const VerificationContext exact = Context(scene, scene.lines);
    const VerifiedPose truth =
        RefineHypothesis(exact, scene.matches, {scene.truth.Planar()}, options_);
    const auto it = std::find(truth.pairs.begin(), truth.pairs.end(), std::make_pair(edge, line));
    ASSERT_NE(it, truth.pairs.end()) << "scene " << scene.index;
    const size_t index = static_cast<size_t>(it - truth.pairs.begin());
    Pose3Dof others;
    Eigen::Matrix4d covariance;
    ASSERT_TRUE(DeletedPose(exact, truth, index, &others, &covariance));
    Eigen::Matrix<double, 3, 4> d_line;
    ProjectedEdgeLine(edges_[edge].a, edges_[edge].b, camera_,
                      ViewOf(others, scene.height, scene.tilt), truth.refinement.focal_scale,
                      &d_line);
    const Eigen::Vector2d mid = scene.lines[line].Mid();
    const Eigen::RowVector4d j = Eigen::Vector3d(mid.x(), mid.y(), 1.0).transpose() * d_line;
    const double sigma_px =
        std::sqrt(noise_.offset_px * noise_.offset_px + (j * covariance * j.transpose())(0, 0));
    // The edge's image replaced by a parallel line kStandInSigmas of those away, which the
    // hypothesis holds: the pose is fit with it (and moves toward it), every pair confident.
    std::vector<Segment2> lines = scene.lines;
    lines[line] = Shifted(lines[line], kStandInSigmas * sigma_px);
    const VerificationContext context = Context(scene, lines);
    VerifiedPose v = RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    v.confident_pairs = v.pairs;
    std::sort(v.confident_pairs.begin(), v.confident_pairs.end());
    const std::vector<std::pair<int, int>> reported = PairsBeatingRivalLines(context, options_, v);
    EXPECT_FALSE(Has(reported, {edge, line}))
        << "scene " << scene.index << ", offset " << kStandInSigmas * sigma_px << " px";
    EXPECT_FALSE(reported.empty()) << "scene " << scene.index;  // the exact pairs remain
    ++tested;
  }
  EXPECT_GE(tested, kScenes / 2);
}

}  // namespace
}  // namespace linetrack

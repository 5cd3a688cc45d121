// Synthetic localisation scenes on the bundled hall: exact scenes lie on their model edges,
// counts and priors respect their bounds, the noise has the configured statistics, and the
// series is a pure function of the seed.
#include "models/synth/synthetic_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "models/errors.h"

namespace linetrack {
namespace {

constexpr double kOnLineTolPx = 1e-6;
constexpr double kVerticalTol = 1e-9;  // |nL_y| of an exact vertical segment's image

// All noise and fragmentation off.
SyntheticSceneOptions ExactOptions(int count) {
  SyntheticSceneOptions o;
  o.count = count;
  o.calibration_sigma = o.angle_sigma = o.offset_sigma_px = 0.0;
  o.shorten_max = o.split_probability = 0.0;
  return o;
}

// The image line (homogeneous, a u + b v + c = 0) of a model edge's infinite line, seen from
// `pose` through `camera` with its focal lengths scaled by `scale`.
Eigen::Vector3d EdgeImageLine(const ModelEdge& edge, const RobotPose& pose,
                              const CameraIntrinsics& camera, double scale) {
  Eigen::Matrix3d k;
  k << scale * camera.px, 0.0, camera.u0, 0.0, scale * camera.py, camera.v0, 0.0, 0.0, 1.0;
  const Eigen::Isometry3d cam_from_world = CamFromWorld(pose);
  return (k * (cam_from_world * edge.segment.a)).cross(k * (cam_from_world * edge.segment.b));
}

double DistanceToLine(const Eigen::Vector3d& line, const Eigen::Vector2d& p) {
  return (line.x() * p.x() + line.y() * p.y() + line.z()) / line.head<2>().norm();
}

class SyntheticScenes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new WireframeModel(
        WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao"));
    area_ = new NavigableArea(NavigableArea::FromModel(*model_));
  }
  static void TearDownTestSuite() {
    delete area_;
    delete model_;
  }

  // Checks that every model line of `scene` lies on its edge's projection (focal lengths scaled
  // by 1 + eps_m) and inside the image.
  static void ExpectLinesOnEdges(const SyntheticScene& scene, const CameraIntrinsics& camera) {
    for (const auto& [edge_id, line_index] : scene.matches) {
      const Eigen::Vector3d line = EdgeImageLine(model_->edges()[edge_id], scene.truth, camera,
                                                 1.0 + scene.calibration_error);
      const Segment2& s = scene.lines[line_index];
      EXPECT_LT(std::abs(DistanceToLine(line, s.a)), kOnLineTolPx) << "edge " << edge_id;
      EXPECT_LT(std::abs(DistanceToLine(line, s.b)), kOnLineTolPx) << "edge " << edge_id;
    }
  }

  static WireframeModel* model_;
  static NavigableArea* area_;
};

WireframeModel* SyntheticScenes::model_ = nullptr;
NavigableArea* SyntheticScenes::area_ = nullptr;

TEST_F(SyntheticScenes, ExactScenesLieOnTheirEdgesWithinBounds) {
  const SyntheticSceneOptions o = ExactOptions(25);
  const std::vector<SyntheticScene> scenes = GenerateScenes(*model_, *area_, o);
  ASSERT_EQ(scenes.size(), 25u);
  for (const SyntheticScene& scene : scenes) {
    EXPECT_EQ(scene.calibration_error, 0.0);
    ExpectLinesOnEdges(scene, o.camera);
    std::set<int> edges;
    for (const auto& m : scene.matches)
      edges.insert(m.first);
    const int visible_edges = static_cast<int>(edges.size());
    const int clutter_lines = static_cast<int>(scene.clutter.size());
    EXPECT_GE(visible_edges, o.min_visible_edges);
    EXPECT_LE(visible_edges, o.max_visible_edges);
    EXPECT_GE(clutter_lines, o.min_clutter);
    EXPECT_LE(clutter_lines, o.max_clutter);
    // Every line is a model line or clutter, exactly once; all inside the image, long enough.
    std::multiset<int> seen(scene.clutter.begin(), scene.clutter.end());
    for (const auto& m : scene.matches)
      seen.insert(m.second);
    ASSERT_EQ(seen.size(), scene.lines.size());
    for (int i = 0; i < static_cast<int>(scene.lines.size()); ++i) {
      EXPECT_EQ(seen.count(i), 1u) << i;
      EXPECT_TRUE(o.camera.Contains(scene.lines[i].a) && o.camera.Contains(scene.lines[i].b));
      EXPECT_GE(scene.lines[i].Length(), o.min_length_px);
    }
    for (int v : scene.vertical_clutter)
      EXPECT_EQ(std::count(scene.clutter.begin(), scene.clutter.end(), v), 1);
    EXPECT_TRUE(area_->Contains({scene.truth.x, scene.truth.y}));
    EXPECT_GE(scene.truth.height, o.height_min);
    EXPECT_LE(scene.truth.height, o.height_max);
    EXPECT_GE(scene.tilt, o.tilt_min);
    EXPECT_LE(scene.tilt, o.tilt_max);
    EXPECT_EQ(scene.height, scene.truth.height);
    EXPECT_LE(std::hypot(scene.prior.x - scene.truth.x, scene.prior.y - scene.truth.y), o.delta_t);
    EXPECT_LE(std::abs(WrapAngle(scene.prior.heading - scene.truth.heading)), o.delta_phi);
  }
}

TEST_F(SyntheticScenes, VerticalClutterImagesVerticalSegments) {
  const SyntheticSceneOptions o = ExactOptions(15);
  int vertical = 0;
  for (const SyntheticScene& scene : GenerateScenes(*model_, *area_, o)) {
    const long third = std::lround(scene.clutter.size() * o.vertical_clutter_fraction);
    EXPECT_LE(static_cast<long>(scene.vertical_clutter.size()), third);
    for (int i : scene.vertical_clutter) {
      const Segment2& s = scene.lines[i];
      const Eigen::Vector3d n = o.camera.Ray(s.a).cross(o.camera.Ray(s.b)).normalized();
      EXPECT_LT(std::abs((LevelFromCam(scene.tilt) * n).y()), kVerticalTol);
      ++vertical;
    }
  }
  EXPECT_GT(vertical, 15);  // most scenes find room for their vertical clutter
}

TEST_F(SyntheticScenes, CalibrationErrorScalesTheFocalLengths) {
  SyntheticSceneOptions o = ExactOptions(10);
  o.calibration_sigma = 0.02;
  int nonzero = 0;
  for (const SyntheticScene& scene : GenerateScenes(*model_, *area_, o)) {
    ExpectLinesOnEdges(scene, o.camera);
    nonzero += scene.calibration_error != 0.0 ? 1 : 0;
    EXPECT_LT(std::abs(scene.calibration_error), 5.0 * o.calibration_sigma);
  }
  EXPECT_EQ(nonzero, 10);
}

TEST_F(SyntheticScenes, FragmentsStayOnTheirEdges) {
  SyntheticSceneOptions o = ExactOptions(20);
  o.shorten_max = 0.15;
  o.split_probability = 0.5;
  int split_edges = 0;
  for (const SyntheticScene& scene : GenerateScenes(*model_, *area_, o)) {
    ExpectLinesOnEdges(scene, o.camera);
    std::set<int> edges;
    for (const auto& m : scene.matches)
      split_edges += edges.insert(m.first).second ? 0 : 1;
  }
  EXPECT_GT(split_edges, 0);  // some edges give two or more lines
}

// Offsets (angle noise off): the noisy line is parallel to the true one, every point of it at
// the drawn offset; the spread over all lines must match the configured sigma.
TEST_F(SyntheticScenes, OffsetNoiseHasTheConfiguredSigma) {
  SyntheticSceneOptions o = ExactOptions(40);
  o.offset_sigma_px = 3.0;
  o.min_visible_edges = 8;  // more lines per scene, fewer scenes
  o.max_visible_edges = 20;
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (const SyntheticScene& scene : GenerateScenes(*model_, *area_, o)) {
    for (const auto& [edge_id, line_index] : scene.matches) {
      const Eigen::Vector3d line =
          EdgeImageLine(model_->edges()[edge_id], scene.truth, o.camera, 1.0);
      const Segment2& s = scene.lines[line_index];
      const double d = DistanceToLine(line, s.a);
      EXPECT_NEAR(DistanceToLine(line, s.b), d, 1e-6);
      sum += d;
      sum2 += d * d;
      ++n;
    }
  }
  ASSERT_GT(n, 300);
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 4.0 * 3.0 / std::sqrt(n));
  EXPECT_NEAR(sigma, 3.0, 4.0 * 3.0 / std::sqrt(2.0 * n));
}

TEST_F(SyntheticScenes, AngleNoiseHasTheConfiguredSigma) {
  SyntheticSceneOptions o = ExactOptions(40);
  o.angle_sigma = DegToRad(1.0);
  o.min_visible_edges = 8;
  o.max_visible_edges = 20;
  double sum2 = 0.0;
  int n = 0;
  for (const SyntheticScene& scene : GenerateScenes(*model_, *area_, o)) {
    for (const auto& [edge_id, line_index] : scene.matches) {
      const Eigen::Vector3d line =
          EdgeImageLine(model_->edges()[edge_id], scene.truth, o.camera, 1.0);
      const Eigen::Vector2d d = scene.lines[line_index].b - scene.lines[line_index].a;
      // Angle between the segment and the true line (normal (a, b)): asin of the normal part.
      const double angle = std::asin(line.head<2>().normalized().dot(d.normalized()));
      sum2 += angle * angle;
      ++n;
    }
  }
  ASSERT_GT(n, 300);
  EXPECT_NEAR(RadToDeg(std::sqrt(sum2 / n)), 1.0, 4.0 / std::sqrt(2.0 * n));
}

bool SameScenes(const std::vector<SyntheticScene>& a, const std::vector<SyntheticScene>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].lines.size() != b[i].lines.size() || a[i].matches != b[i].matches ||
        a[i].prior.x != b[i].prior.x || a[i].truth.heading != b[i].truth.heading) {
      return false;
    }
    for (size_t k = 0; k < a[i].lines.size(); ++k) {
      if (a[i].lines[k].a != b[i].lines[k].a || a[i].lines[k].b != b[i].lines[k].b) return false;
    }
  }
  return true;
}

TEST_F(SyntheticScenes, SeedDecidesEverything) {
  SyntheticSceneOptions o;
  o.count = 6;
  const std::vector<SyntheticScene> first = GenerateScenes(*model_, *area_, o);
  EXPECT_TRUE(SameScenes(first, GenerateScenes(*model_, *area_, o)));
  // A scene does not depend on how many follow it.
  SyntheticSceneOptions fewer = o;
  fewer.count = 3;
  const std::vector<SyntheticScene> head = GenerateScenes(*model_, *area_, fewer);
  EXPECT_TRUE(SameScenes(head, {first.begin(), first.begin() + 3}));
  SyntheticSceneOptions other = o;
  other.seed = 2;
  const std::vector<SyntheticScene> different = GenerateScenes(*model_, *area_, other);
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_FALSE(SameScenes({first[i]}, {different[i]})) << i;
  }
}

TEST(SyntheticSceneOptions, CheckRejectsBadValues) {
  std::string why;
  EXPECT_TRUE(SyntheticSceneOptions().Check(&why)) << why;
  auto rejects = [](auto edit) {
    SyntheticSceneOptions o;
    edit(o);
    std::string reason;
    return !o.Check(&reason) && !reason.empty();
  };
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.count = 0; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.height_min = NAN; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.height_max = 1.0; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.tilt_max = DegToRad(95.0); }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.offset_sigma_px = -1.0; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.delta_phi = 0.0; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.delta_t = INFINITY; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.min_clutter = 13; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.camera.width = 0; }));
  EXPECT_TRUE(rejects([](SyntheticSceneOptions& o) { o.split_probability = 1.5; }));
  EXPECT_NEAR(QualityIndexBounds(3).delta_t, 0.75, 1e-12);
  EXPECT_NEAR(RadToDeg(QualityIndexBounds(2).delta_phi), 15.0, 1e-12);
  EXPECT_THROW(QualityIndexBounds(4), InputError);
}

TEST(SyntheticNoise, PerturbRotatesAboutTheMidpointAndShiftsAlongTheNormal) {
  const Segment2 s{{100.0, 100.0}, {200.0, 100.0}};
  const Segment2 p = PerturbSegment(s, DegToRad(90.0), 5.0);
  // Rotated to vertical (pointing +v), normal (-1, 0): midpoint moves to (145, 100).
  EXPECT_LT((p.Mid() - Eigen::Vector2d(145.0, 100.0)).norm(), 1e-9);
  EXPECT_NEAR(p.Length(), 100.0, 1e-9);
  EXPECT_NEAR(std::abs(p.a.x() - p.b.x()), 0.0, 1e-9);
}

TEST(SyntheticNoise, FragmentShortensAndSplits) {
  const Segment2 s{{0.0, 0.0}, {100.0, 0.0}};
  const std::vector<Segment2> one = FragmentSegment(s, 0.1, 0.05, 0.5, 0.0);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].a.x(), 10.0, 1e-9);
  EXPECT_NEAR(one[0].b.x(), 95.0, 1e-9);
  const std::vector<Segment2> two = FragmentSegment(s, 0.1, 0.05, 0.4, 0.1);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NEAR(two[0].b.x(), 35.0, 1e-9);
  EXPECT_NEAR(two[1].a.x(), 45.0, 1e-9);
  EXPECT_EQ(FragmentSegment(s, 0.1, 0.1, 0.05, 0.05).size(), 1u);  // first piece vanishes
}

TEST(SyntheticNoise, RandomDrawsHaveTheirDistributions) {
  SceneRandom rng(7, 0);
  constexpr int kDraws = 20000;
  double sum = 0.0, sum2 = 0.0;
  int low = 0, high = 0;
  for (int i = 0; i < kDraws; ++i) {
    const double x = rng.Normal(2.0);
    sum += x;
    sum2 += x * x;
    const int k = rng.Integer(5, 12);
    ASSERT_GE(k, 5);
    ASSERT_LE(k, 12);
    low += k == 5 ? 1 : 0;
    high += k == 12 ? 1 : 0;
  }
  EXPECT_NEAR(sum / kDraws, 0.0, 0.06);
  EXPECT_NEAR(std::sqrt(sum2 / kDraws), 2.0, 0.06);
  EXPECT_NEAR(low, kDraws / 8, 200);
  EXPECT_NEAR(high, kDraws / 8, 200);
  SceneRandom a(7, 3), b(7, 3), c(7, 4);
  const double x = a.Uniform(0.0, 1.0);
  EXPECT_EQ(x, b.Uniform(0.0, 1.0));
  EXPECT_NE(x, c.Uniform(0.0, 1.0));
}

}  // namespace
}  // namespace linetrack

// The casing evidence of a frame line (tracking/tracker/casing_evidence.h) on exact synthetic
// images: a vertical door jamb 3 m in front of a px = 500 camera, with or without a 7 cm casing
// band beside it, sharp or blurred across by the head's sweep.
#include "tracking/tracker/casing_evidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/tracking/integrity_scene.h"

namespace linetrack {
namespace {

constexpr double kDepthM = 3.0;
constexpr double kCasingM = 0.07;
// The width found is the ridge's sub-sample offset at 0.5 px steps: 0.25 px at 167 px/m.
constexpr double kWidthToleranceM = 0.004;

CameraIntrinsics Camera() {
  return integrity_test::TestCamera();
}

// Grey level at column position x (pixels, continuous): door leaf right of the jamb's image at
// u = 320, wall left, and with `band` the casing's trim between the wall and the jamb.
double Scene(double x, bool band) {
  const double band_px = Camera().px * kCasingM / kDepthM;
  if (x >= 320.0) return 80.0;
  if (band && x >= 320.0 - band_px) return 200.0;
  return 150.0;
}

// Each pixel the mean of the scene over its width, also over `blur_px` of motion across it.
vpImage<unsigned char> Render(bool band, double blur_px) {
  vpImage<unsigned char> image(480, 640);
  const double extent = 1.0 + blur_px;
  const int samples = 64;
  for (unsigned u = 0; u < 640; ++u) {
    double sum = 0.0;
    for (int s = 0; s < samples; ++s)
      sum += Scene(u - 0.5 * extent + extent * (s + 0.5) / samples, band);
    const unsigned char value = static_cast<unsigned char>(std::lround(sum / samples));
    for (unsigned v = 0; v < 480; ++v)
      image[v][u] = value;
  }
  return image;
}

// The jamb in the camera frame (cam_from_world = identity): x = 0, on the wall z = 3, and its
// points every 8 px on its image. The band lies on -x: casing_direction (-1, 0, 0).
EdgeObservation Jamb() {
  EdgeObservation e;
  e.a = Eigen::Vector3d(0.0, -0.4, kDepthM);
  e.b = Eigen::Vector3d(0.0, 0.4, kDepthM);
  e.casing_direction = Eigen::Vector3d(-1.0, 0.0, 0.0);
  for (double v = 180.0; v <= 300.0; v += 8.0)
    e.points.emplace_back(320.0, v);
  return e;
}

TEST(CasingEvidence, SeesTheBandBesideASharpJambAtItsWidth) {
  const CasingEvidence found = FindCasing(
      Render(true, 0.0), Camera(), Eigen::Isometry3d::Identity(), Jamb(), CasingEvidenceOptions());
  EXPECT_EQ(found.verdict, CasingVerdict::kSeen);
  EXPECT_EQ(found.examined, static_cast<int>(Jamb().points.size()));
  EXPECT_EQ(found.with_ridge, found.examined);
  EXPECT_NEAR(found.width_m, kCasingM, kWidthToleranceM);
}

TEST(CasingEvidence, FindsNoneBesideASharpJambWithoutABand) {
  const CasingEvidence found = FindCasing(
      Render(false, 0.0), Camera(), Eigen::Isometry3d::Identity(), Jamb(), CasingEvidenceOptions());
  EXPECT_EQ(found.verdict, CasingVerdict::kAbsent);
  EXPECT_EQ(found.examined, static_cast<int>(Jamb().points.size()));
  EXPECT_EQ(found.with_ridge, 0);
}

TEST(CasingEvidence, AShortJambRulesNothingOutButReportsItsRidges) {
  // Four points: too few to rule a casing out, the band's border still measured on each.
  EdgeObservation jamb = Jamb();
  jamb.points.resize(4);
  const CasingEvidence found = FindCasing(
      Render(true, 0.0), Camera(), Eigen::Isometry3d::Identity(), jamb, CasingEvidenceOptions());
  EXPECT_EQ(found.verdict, CasingVerdict::kUnclear);
  EXPECT_EQ(found.examined, 4);
  EXPECT_EQ(found.with_ridge, 4);
  EXPECT_NEAR(found.width_m, kCasingM, kWidthToleranceM);
}

TEST(CasingEvidence, ABlurredJambRulesNothingOut) {
  // 12 px of motion across the jamb: the band's border merges with the jamb's step.
  for (bool band : {false, true}) {
    const CasingEvidence found =
        FindCasing(Render(band, 12.0), Camera(), Eigen::Isometry3d::Identity(), Jamb(),
                   CasingEvidenceOptions());
    EXPECT_EQ(found.verdict, CasingVerdict::kUnclear) << "band " << band;
  }
}

TEST(CasingEvidence, OnlyTheJambWithoutABandLosesItsAllowance) {
  std::vector<EdgeObservation> edges = {Jamb()};
  EXPECT_EQ(ClearCasingsNotSeen(Render(true, 0.0), Camera(), Eigen::Isometry3d::Identity(),
                                CasingEvidenceOptions(), &edges),
            0);
  EXPECT_FALSE(edges[0].casing_direction.isZero());
  EXPECT_EQ(ClearCasingsNotSeen(Render(false, 0.0), Camera(), Eigen::Isometry3d::Identity(),
                                CasingEvidenceOptions(), &edges),
            1);
  EXPECT_TRUE(edges[0].casing_direction.isZero());
  CasingEvidenceOptions off;
  off.enabled = false;
  std::vector<EdgeObservation> kept = {Jamb()};
  EXPECT_EQ(
      ClearCasingsNotSeen(Render(false, 0.0), Camera(), Eigen::Isometry3d::Identity(), off, &kept),
      0);
  EXPECT_FALSE(kept[0].casing_direction.isZero());
}

}  // namespace
}  // namespace linetrack

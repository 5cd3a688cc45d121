// Vanishing-point geometry on exact projections of the hall: the images of vertical edges point
// at DownInCamera(tilt), those of horizontal edges at their direction's vanishing point, and each
// horizontal edge's bearing gives the heading modulo pi.
#include "matching/heading/vanishing_geometry.h"

#include <gtest/gtest.h>

#include "matching/heading/model_directions.h"
#include "models/robot_pose.h"
#include "tests/matching/scene_fixture.h"

namespace linetrack {
namespace {

constexpr double kExactTol = 1e-9;       // radians, residual of an exact relation
constexpr double kDerivativeTol = 1e-5;  // relative, analytic against finite differences
constexpr int kViews = 100;

class VanishingGeometryTest : public ::testing::Test {
 protected:
  testing::HallFixture hall_;
};

TEST_F(VanishingGeometryTest, ImageDirectionIsTheDerivativeOfTheProjection) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), unit(-1.0, 1.0);
  const CameraIntrinsics& camera = hall_.camera();
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d uv(u(rng), v(rng));
    const Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
    constexpr double kStep = 1e-6;
    const Eigen::Vector2d numeric =
        (camera.Project(camera.Ray(uv) + kStep * d) - camera.Project(camera.Ray(uv) - kStep * d)) /
        (2.0 * kStep);
    const Eigen::Vector2d analytic = ImageDirectionToward(camera, uv, d);
    EXPECT_LT((numeric - analytic).norm(), kDerivativeTol * (1.0 + analytic.norm()));
  }
}

TEST_F(VanishingGeometryTest, ExactEdgeImagesPointAtTheirVanishingPoints) {
  std::mt19937_64 rng(5);
  for (int n = 0; n < kViews; ++n) {
    const testing::ExactView view = hall_.RandomView(rng);
    const Eigen::Matrix3d rotation = CamFromWorldRotation(view.pose.heading, view.pose.tilt);
    const Eigen::Matrix3d level = LevelFromCam(view.pose.tilt);
    for (const ProjectedEdge& piece : view.pieces) {
      const ModelEdge& edge = hall_.model().edges()[piece.edge_id];
      const Eigen::Vector3d dir = edge.segment.Direction();
      const Eigen::Vector3d normal = InterpretationNormal(hall_.camera(), piece.image);
      EXPECT_NEAR(VanishingResidual(hall_.camera(), piece.image, rotation * dir), 0.0, 1e-7);
      if (edge.vertical) {
        EXPECT_NEAR(VanishingResidual(hall_.camera(), piece.image, DownInCamera(view.pose.tilt)),
                    0.0, 1e-7);
        EXPECT_NEAR(TiltMakingHorizontal(normal), view.pose.tilt, kExactTol);
      } else {
        const double theta = std::atan2(dir.y(), dir.x());
        const double alpha = HorizontalBearing(level * normal);
        EXPECT_NEAR(WrapCentred(HeadingFromBearing(theta, alpha) - view.pose.heading, kPi), 0.0,
                    kExactTol);
        // A horizontal direction's vanishing point lies on the horizon of the tilt.
        EXPECT_NEAR(TiltMakingHorizontal(rotation * dir), view.pose.tilt, kExactTol);
      }
    }
  }
}

TEST_F(VanishingGeometryTest, VanishingPixelIsWhereDistantPointsProject) {
  const CameraIntrinsics& camera = hall_.camera();
  const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  const Eigen::Vector3d start(1.0, 0.5, 2.0);
  const std::optional<Eigen::Vector2d> vp = VanishingPixel(camera, d);
  ASSERT_TRUE(vp.has_value());
  EXPECT_LT((camera.Project(start + 1e9 * d) - *vp).norm(), 1e-5);
  // The opposite direction has the same vanishing point; one parallel to the image has none.
  EXPECT_LT((*VanishingPixel(camera, -d) - *vp).norm(), 1e-9);
  EXPECT_FALSE(VanishingPixel(camera, Eigen::Vector3d(1.0, 0.5, 0.0)).has_value());
}

TEST_F(VanishingGeometryTest, WrapsToTheirPeriods) {
  EXPECT_NEAR(WrapPositive(-0.5, kPi), kPi - 0.5, kExactTol);
  EXPECT_NEAR(WrapPositive(7.0, 2.0 * kPi), 7.0 - 2.0 * kPi, kExactTol);
  EXPECT_NEAR(WrapCentred(kPi - 0.1, kPi), -0.1, kExactTol);
  EXPECT_NEAR(WrapCentred(0.1, kPi), 0.1, kExactTol);
}

TEST_F(VanishingGeometryTest, HallDirectionsAreTheAxesWithAQuarterTurnSymmetry) {
  const ModelDirections dirs = DominantDirections(hall_.model());
  ASSERT_EQ(dirs.angles.size(), 2u);
  EXPECT_NEAR(dirs.angles[0], 0.0, kExactTol);
  EXPECT_NEAR(dirs.angles[1], kPi / 2.0, kExactTol);
  const std::vector<double> sym = dirs.Symmetries(DegToRad(0.5));
  ASSERT_EQ(sym.size(), 2u);
  EXPECT_NEAR(sym[1], kPi / 2.0, kExactTol);
}

TEST_F(VanishingGeometryTest, SymmetriesOfOtherDirectionSets) {
  const double tol = DegToRad(0.5);
  EXPECT_EQ(DirectionsFromAngles({0.0, DegToRad(30.0)}, tol).Symmetries(tol).size(), 1u);
  const ModelDirections hexagonal =
      DirectionsFromAngles({0.0, DegToRad(60.0), DegToRad(-60.0)}, tol);
  EXPECT_EQ(hexagonal.Symmetries(tol).size(), 3u);
  // Directions within the merge distance are one; angles are taken modulo pi.
  const ModelDirections merged =
      DirectionsFromAngles({DegToRad(10.0), DegToRad(190.5)}, DegToRad(2.0));
  ASSERT_EQ(merged.angles.size(), 1u);
  EXPECT_NEAR(RadToDeg(merged.angles[0]), 10.25, 1e-6);
}

}  // namespace
}  // namespace linetrack

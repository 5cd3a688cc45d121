// The maths of app/ros/ros_geometry.h on exact synthetic poses: the camera mount, AMCL's
// map -> odom correction, the pose covariance's Jacobian against finite differences, odometry
// interpolation and the matcher's bounds from RViz's initial pose covariance.
#include "app/ros/ros_geometry.h"

#include <gtest/gtest.h>

#include "models/geometry.h"

namespace linetrack::app {
namespace {

constexpr double kExact = 1e-9;
constexpr double kFiniteDifferenceStep = 1e-6;
constexpr double kFiniteDifferenceTol = 1e-5;  // first-order Jacobian vs central differences

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& r) {
  const double a = r.norm();
  if (a == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, r / a).toRotationMatrix();
}

// A camera 1.3 m above a base at (2, 3) heading 40 degrees, panned 25 and tilted 10 degrees.
struct Scene {
  CameraMount mount{1.3, DegToRad(25.0), DegToRad(10.0)};
  Pose3Dof base{2.0, 3.0, DegToRad(40.0)};
  Eigen::Isometry3d map_from_base = PlanarIsometry(base);
  Eigen::Isometry3d cam_from_map = (map_from_base * BaseFromCamera(mount)).inverse();
};

TEST(RosGeometry, TheMountedCameraSeesWhatTheRobotPoseSays) {
  const Scene s;
  const Eigen::Isometry3d expected = CamFromWorld(CameraPrior(s.base, s.mount));
  EXPECT_TRUE(s.cam_from_map.isApprox(expected, kExact));
  EXPECT_TRUE(MapFromBase(s.cam_from_map, s.mount).isApprox(s.map_from_base, kExact));
  const Pose3Dof planar = PlanarOf(s.map_from_base);
  EXPECT_NEAR(planar.heading, s.base.heading, kExact);
}

TEST(RosGeometry, MapFromOdomComposesBackToTheTrackedBase) {
  const Scene s;
  const Eigen::Isometry3d odom_from_base = PlanarIsometry({0.4, -1.0, DegToRad(-70.0)});
  const Eigen::Isometry3d map_from_odom = MapFromOdom(s.map_from_base, odom_from_base);
  EXPECT_TRUE((map_from_odom * odom_from_base).isApprox(s.map_from_base, kExact));
}

TEST(RosGeometry, LeftJacobianMatchesFiniteDifferences) {
  const Eigen::Vector3d r(0.3, -0.8, 1.1);
  const Eigen::Matrix3d j = LeftJacobianSO3(r);
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d dr = kFiniteDifferenceStep * Eigen::Vector3d::Unit(k);
    const Eigen::Vector3d plus = RotationVector(Exp(r + dr) * Exp(r).transpose());
    const Eigen::Vector3d minus = RotationVector(Exp(r - dr) * Exp(r).transpose());
    const Eigen::Vector3d numeric = (plus - minus) / (2.0 * kFiniteDifferenceStep);
    EXPECT_LT((numeric - j.col(k)).norm(), kFiniteDifferenceTol) << "column " << k;
  }
}

// The base's pose for the parameters p = (t, theta u) of cMo: (B, R_wb).
Eigen::Isometry3d BaseOfParameters(const Eigen::Matrix<double, 6, 1>& p,
                                   const Eigen::Isometry3d& base_from_cam) {
  Eigen::Isometry3d cam_from_map = Eigen::Isometry3d::Identity();
  cam_from_map.translation() = p.head<3>();
  cam_from_map.linear() = Exp(p.tail<3>());
  return cam_from_map.inverse() * base_from_cam.inverse();
}

TEST(RosGeometry, PoseCovarianceJacobianMatchesFiniteDifferences) {
  const Scene s;
  const Eigen::Isometry3d base_from_cam = BaseFromCamera(s.mount);
  Eigen::Matrix<double, 6, 1> p;
  p << s.cam_from_map.translation(), RotationVector(s.cam_from_map.linear());
  const Matrix6d m = RosPoseJacobian(s.cam_from_map, base_from_cam);
  const Eigen::Isometry3d base = BaseOfParameters(p, base_from_cam);
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix<double, 6, 1> dp =
        kFiniteDifferenceStep * Eigen::Matrix<double, 6, 1>::Unit(k);
    const Eigen::Isometry3d plus = BaseOfParameters(p + dp, base_from_cam);
    const Eigen::Isometry3d minus = BaseOfParameters(p - dp, base_from_cam);
    Eigen::Matrix<double, 6, 1> numeric;
    numeric.head<3>() = (plus.translation() - minus.translation()) / (2 * kFiniteDifferenceStep);
    // Rotation about the map's fixed axes: R' = exp([w]x) R.
    numeric.tail<3>() = (RotationVector(plus.linear() * base.linear().transpose()) -
                         RotationVector(minus.linear() * base.linear().transpose())) /
                        (2 * kFiniteDifferenceStep);
    EXPECT_LT((numeric - m.col(k)).norm(), kFiniteDifferenceTol) << "parameter " << k;
  }
  // The covariance is M Sigma M^T, symmetric.
  Matrix6d sigma = Matrix6d::Identity() * 1e-4;
  sigma(0, 3) = sigma(3, 0) = 2e-5;
  const Matrix6d ros = RosPoseCovariance(sigma, s.cam_from_map, base_from_cam);
  EXPECT_TRUE(ros.isApprox(m * sigma * m.transpose(), kExact));
  EXPECT_TRUE(ros.isApprox(ros.transpose(), kExact));
}

TEST(RosGeometry, OdometryIsInterpolatedAtTheImageStamp) {
  const std::vector<StampedOdometry> readings = {
      {10.0, PlanarIsometry({0.0, 0.0, 0.0})}, {10.2, PlanarIsometry({0.2, 0.4, DegToRad(20.0)})}};
  const std::optional<Eigen::Isometry3d> mid = OdometryAt(readings, 10.05, 0.1);
  ASSERT_TRUE(mid.has_value());
  const Pose3Dof planar = PlanarOf(*mid);
  EXPECT_NEAR(planar.x, 0.05, kExact);
  EXPECT_NEAR(planar.y, 0.1, kExact);
  EXPECT_NEAR(planar.heading, DegToRad(5.0), kExact);
  EXPECT_TRUE(OdometryAt(readings, 10.25, 0.1).has_value());   // within the gap
  EXPECT_FALSE(OdometryAt(readings, 10.35, 0.1).has_value());  // beyond it
  EXPECT_FALSE(OdometryAt({}, 10.0, 0.1).has_value());
}

TEST(RosGeometry, RvizInitialPoseGivesThePapersBounds) {
  Matrix6d rviz = Matrix6d::Zero();
  rviz(0, 0) = rviz(1, 1) = 0.25;
  rviz(5, 5) = 0.06853891945200942;
  const SearchBounds bounds = BoundsFromCovariance(rviz, RelocalizationOptions());
  EXPECT_NEAR(bounds.delta_t, 0.75, kExact);
  EXPECT_NEAR(RadToDeg(bounds.delta_phi), 1.5 * RadToDeg(std::sqrt(rviz(5, 5))), kExact);
  // A certain pose still gets the smallest bounds after a loss; a vague one the widest.
  const SearchBounds tight = BoundsFromCovariance(Matrix6d::Zero(), RelocalizationOptions());
  EXPECT_NEAR(tight.delta_t, RelocalizationOptions().after_loss.delta_t, kExact);
  const SearchBounds wide =
      BoundsFromCovariance(Matrix6d::Identity() * 100.0, RelocalizationOptions());
  EXPECT_NEAR(wide.delta_t, RelocalizationOptions().max.delta_t, kExact);
}

}  // namespace
}  // namespace linetrack::app

// The maths of app/ros/ros_geometry.h on exact synthetic poses: the camera mount, AMCL's
// map -> odom correction, the pose covariance in ROS's convention, the status, odometry
// interpolation and the matcher's bounds from RViz's initial pose covariance.
#include "app/ros/ros_geometry.h"

#include <gtest/gtest.h>

#include <array>

#include "app/ros/camera_mount_source.h"
#include "app/ros/newest_only.h"
#include "app/ros/ros_tracker.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"

namespace linetrack::app {
namespace {

constexpr double kExact = 1e-9;

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

// A camera 0.2 m ahead of and 0.05 m right of the base's origin (a head's offset from TF): the
// tracker's prior is at its optical centre, and the tracked camera gives the base back.
TEST(RosGeometry, AnOffsetCameraSeesWhatTheRobotPoseSays) {
  Scene s;
  s.mount.x = 0.2;
  s.mount.y = -0.05;
  s.cam_from_map = (s.map_from_base * BaseFromCamera(s.mount)).inverse();
  EXPECT_TRUE(s.cam_from_map.isApprox(CamFromWorld(CameraPrior(s.base, s.mount)), kExact));
  EXPECT_TRUE(MapFromBase(s.cam_from_map, s.mount).isApprox(s.map_from_base, kExact));
  // The optical centre in the map, by hand: base + Rz(40 deg) (0.2, -0.05).
  const double c = std::cos(DegToRad(40.0)), n = std::sin(DegToRad(40.0));
  const RobotPose prior = CameraPrior(s.base, s.mount);
  EXPECT_NEAR(prior.x, 2.0 + c * 0.2 + n * 0.05, kExact);
  EXPECT_NEAR(prior.y, 3.0 + n * 0.2 - c * 0.05, kExact);
}

// A camera rolled on its mount: the tracker's prior carries the roll and is the camera.
TEST(RosGeometry, ARolledCamerasPriorIsTheCamera) {
  Scene s;
  s.mount.roll = DegToRad(-2.0);
  s.cam_from_map = (s.map_from_base * BaseFromCamera(s.mount)).inverse();
  const RobotPose prior = CameraPrior(s.base, s.mount);
  EXPECT_NEAR(prior.roll, s.mount.roll, kExact);
  EXPECT_TRUE(s.cam_from_map.isApprox(CamFromWorld(prior), kExact));
}

// TF gives base_from_cam: its mount (pan, tilt, roll, offsets) composes back to it exactly, and a
// positive roll turns the image's x axis towards the image's y (down).
TEST(RosGeometry, TheMountOfATransformComposesBackToIt) {
  const std::array<CameraMount, 4> mounts = {
      CameraMount{1.3, DegToRad(25.0), DegToRad(10.0), 0.2, -0.05, 0.0},
      CameraMount{0.4, DegToRad(-170.0), DegToRad(-30.0), -0.1, 0.3, DegToRad(3.0)},
      CameraMount{2.0, DegToRad(90.0), DegToRad(60.0), 0.0, 0.0, DegToRad(-20.0)},
      CameraMount{1.0, 0.0, 0.0, 0.0, 0.0, DegToRad(170.0)}};
  for (const CameraMount& m : mounts) {
    const Eigen::Isometry3d base_from_cam = BaseFromCamera(m);
    const CameraMount got = MountOfBaseFromCamera(base_from_cam);
    EXPECT_NEAR(WrapAngle(got.pan - m.pan), 0.0, kExact);
    EXPECT_NEAR(got.tilt, m.tilt, kExact);
    EXPECT_NEAR(WrapAngle(got.roll - m.roll), 0.0, kExact);
    EXPECT_NEAR(got.x, m.x, kExact);
    EXPECT_NEAR(got.y, m.y, kExact);
    EXPECT_NEAR(got.height, m.height, kExact);
    EXPECT_TRUE(BaseFromCamera(got).isApprox(base_from_cam, kExact));
    // The image's x axis x = cos(roll) r + sin(roll) d, r level and d = f x r with
    // d_z = -cos(tilt): its height is -sin(roll) cos(tilt).
    const Eigen::Vector3d image_x = base_from_cam.linear().col(0);
    EXPECT_NEAR(image_x.z(), -std::sin(m.roll) * std::cos(m.tilt), kExact);
  }
}

// A calibrated camera on a pan-tilt head (76.5 mm left of, 10 mm ahead of and 68 mm above the
// axes' crossing, turned 1 degree in yaw, pitch and roll off the tilt frame's axes, on a base
// tilted 0.4 degrees in roll and -0.7 in pitch): the node's mount at joint angles (pan, tilt) is
// base_from_camera = T(0, 0, h) level_from_base Rz(pan) Ry(tilt) tilt_from_camera, composed here
// by hand, at several angles.
TEST(RosGeometry, AMountOnTheHeadIsTheHeadsCameraPose) {
  HeadGeometry head;
  head.tilt_from_camera = AlignedMount(Eigen::Vector3d(0.010, 0.0765, 0.068), CameraRoll::kUpright);
  head.tilt_from_camera.linear() = (Eigen::AngleAxisd(DegToRad(1.0), Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(DegToRad(-1.0), Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(DegToRad(1.0), Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix() *
                                   head.tilt_from_camera.linear();
  head.level_from_base = LevelFromBaseRotation(DegToRad(0.4), DegToRad(-0.7));
  const double h = 1.23;
  const std::array<std::array<double, 2>, 4> angles = {
      {{25.0, 10.0}, {-40.0, -15.0}, {170.0, 30.0}, {0.0, 0.0}}};
  for (const auto& [pan_deg, tilt_deg] : angles) {
    const double pan = DegToRad(pan_deg), tilt = DegToRad(tilt_deg);
    Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
    expected.translation() = Eigen::Vector3d(0.0, 0.0, h);
    expected.linear() = head.level_from_base *
                        Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                        Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()).toRotationMatrix();
    expected = expected * head.tilt_from_camera;
    const CameraMount mount = MountOnHead(head, h, pan, tilt);
    std::string why;
    EXPECT_TRUE(mount.Check(&why)) << why;
    EXPECT_TRUE(BaseFromCamera(mount).isApprox(expected, kExact))
        << "pan " << pan_deg << " tilt " << tilt_deg << "\n"
        << BaseFromCamera(mount).matrix() << "\n"
        << expected.matrix();
  }
}

// With the camera upright at the crossing on a level base, the mount is the node's mount without
// a mount file: the joints' pan and tilt at the crossing's height.
TEST(RosGeometry, ACameraAtTheCrossingHasTheJointsAngles) {
  const HeadGeometry head;
  const CameraMount mount = MountOnHead(head, 1.3, DegToRad(20.0), DegToRad(7.0));
  EXPECT_NEAR(mount.height, 1.3, kExact);
  EXPECT_NEAR(mount.pan, DegToRad(20.0), kExact);
  EXPECT_NEAR(mount.tilt, DegToRad(7.0), kExact);
  EXPECT_NEAR(mount.x, 0.0, kExact);
  EXPECT_NEAR(mount.y, 0.0, kExact);
  EXPECT_NEAR(mount.roll, 0.0, kExact);
}

// The InputError message of options.Check(), or "" when it does not throw.
std::string CheckMessage(const CameraMountSourceOptions& options) {
  try {
    options.Check();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A mount file applies to the joints' angles: refused with TF or a fixed mount, and it makes the
// height optional (its floor height, or BelieveHead asks for --height).
TEST(RosMountOptions, AMountFileGoesWithJointStatesOnly) {
  CameraMountSourceOptions o;
  o.mount = "mount.json";
  o.tilt = DegToRad(5.0);
  for (HeadSource head : {HeadSource::kTf, HeadSource::kFixed, HeadSource::kAuto}) {
    o.head = head;
    o.height = 1.3;
    EXPECT_NE(CheckMessage(o).find("--mount"), std::string::npos) << CheckMessage(o);
  }
  o.head = HeadSource::kAuto;
  o.pan_joint = "head_pan";
  o.height = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(CheckMessage(o), "");
  o.head = HeadSource::kJointStates;
  EXPECT_EQ(CheckMessage(o), "");
  o.mount.clear();
  EXPECT_NE(CheckMessage(o).find("--height"), std::string::npos) << CheckMessage(o);
}

TEST(RosGeometry, MapFromOdomComposesBackToTheTrackedBase) {
  const Scene s;
  const Eigen::Isometry3d odom_from_base = PlanarIsometry({0.4, -1.0, DegToRad(-70.0)});
  const Eigen::Isometry3d map_from_odom = MapFromOdom(s.map_from_base, odom_from_base);
  EXPECT_TRUE((map_from_odom * odom_from_base).isApprox(s.map_from_base, kExact));
}

// The base's origin is below the optical centre and turns with the camera about z: a twist
// covariance in the camera centre's x, y and the heading (omega_z) alone is the base's x, y, yaw
// covariance; without a covariance there is none.
TEST(RosGeometry, PlanarTwistCovarianceIsTheBasesXYYaw) {
  const Scene s;
  Matrix6d twist = Matrix6d::Zero();
  twist(0, 0) = 4e-4;
  twist(1, 1) = 1e-4;
  twist(0, 1) = twist(1, 0) = -5e-5;
  twist(5, 5) = 3e-5;
  twist(0, 5) = twist(5, 0) = 2e-5;
  PoseUncertainty u;
  u.world_covariance = twist;
  const std::optional<Matrix6d> ros = RosCovarianceOf(u, s.cam_from_map, s.mount);
  ASSERT_TRUE(ros.has_value());
  const std::array<int, 3> planar = {0, 1, 5};
  for (int i : planar) {
    for (int j : planar) {
      EXPECT_NEAR((*ros)(i, j), twist(i, j), kExact) << i << "," << j;
    }
  }
  const Eigen::Matrix3d z_roll_pitch = ros->block<3, 3>(2, 2);
  EXPECT_NEAR(z_roll_pitch.norm(), 0.0, kExact);  // z, roll, pitch: known
  EXPECT_FALSE(RosCovarianceOf(PoseUncertainty(), s.cam_from_map, s.mount).has_value());
}

// ~status of a frame with a pose: the integrity monitor's word, relocalising for a degraded pose
// while the matcher's pose is being confirmed.
TEST(RosGeometry, StatusFollowsTheIntegrityMonitor) {
  EXPECT_EQ(StatusOf(IntegrityStatus::kTracking, /*reacquiring=*/false), RosStatus::kTracking);
  EXPECT_EQ(StatusOf(IntegrityStatus::kDegraded, /*reacquiring=*/false), RosStatus::kDegraded);
  EXPECT_EQ(StatusOf(IntegrityStatus::kDegraded, /*reacquiring=*/true), RosStatus::kRelocalising);
  EXPECT_EQ(StatusOf(IntegrityStatus::kLost, /*reacquiring=*/false), RosStatus::kLost);
  EXPECT_STREQ(ToString(RosStatus::kRelocalising), "relocalising");
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

TEST(RosGeometry, HeadAnglesAreInterpolatedAtTheImageStamp) {
  const std::vector<StampedHeadAngles> readings = {{10.0, 0.1, 0.2}, {10.2, 0.3, 0.1}};
  const std::optional<StampedHeadAngles> mid = HeadAnglesAt(readings, 10.05, 0.1);
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(mid->pan, 0.15, kExact);
  EXPECT_NEAR(mid->tilt, 0.175, kExact);
  const std::optional<StampedHeadAngles> before = HeadAnglesAt(readings, 9.95, 0.1);
  ASSERT_TRUE(before.has_value());  // within the gap: the first reading
  EXPECT_NEAR(before->pan, 0.1, kExact);
  EXPECT_FALSE(HeadAnglesAt(readings, 10.35, 0.1).has_value());  // beyond it
  EXPECT_FALSE(HeadAnglesAt({}, 10.0, 0.1).has_value());
}

// Images arriving faster than they are tracked: the waiting one is replaced by the newer, each
// replacement reported (and counted by the node), the newest taken next.
TEST(RosNodeQueue, TheOldestWaitingImageIsDropped) {
  NewestOnly<int> slot;
  EXPECT_FALSE(slot.Put(1));
  EXPECT_TRUE(slot.Put(2));
  EXPECT_TRUE(slot.Put(3));
  ASSERT_TRUE(slot.waiting());
  EXPECT_EQ(slot.Take(), std::optional<int>(3));
  EXPECT_FALSE(slot.waiting());
  EXPECT_FALSE(slot.Take().has_value());
  EXPECT_FALSE(slot.Put(4));  // nothing waiting: nothing dropped
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

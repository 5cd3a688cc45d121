// `linetrack replay --input RUN.bag`: a bag written here (rendered hall frames, the robot's
// odometry in its own odom frame, the pan-tilt head's joint states) is replayed from --prior; the
// poses carry the bag's stamps and match the truth, and --out-bag holds the poses with their
// covariance and map -> odom. Bad bags (missing topic, wrong type, truncated, unindexed) exit 2
// with one line and write nothing.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <fstream>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_messages.h"
#include "models/trajectory_io.h"
#include "tests/app/ros_test_scene.h"
#include "tests/support/cli_test.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;
const std::string kSource = LINETRACK_SOURCE_DIR;

constexpr int kFrames = 20;
constexpr double kPanAmplitudeDeg = 10.0;
constexpr double kPositionTolM = 0.05;  // camera centre and base position vs truth
constexpr double kYawTolDeg = 1.0;
constexpr double kStampTolS = 1e-6;
constexpr int kMaxFramesWithoutPose = 3;

// The run, written once for the suite.
struct BagRun {
  test::RenderedDrive drive = test::RenderHallDrive(kFrames, DegToRad(kPanAmplitudeDeg));
  fs::path bag = fs::path(LINETRACK_BINARY_DIR) / "test_output" / "ros_bag_run.bag";

  BagRun() {
    fs::create_directories(bag.parent_path());
    rosbag::Bag out(bag.string(), rosbag::bagmode::Write);
    const Eigen::Isometry3d odom_from_map = PlanarIsometry(drive.frames[0].base.Planar()).inverse();
    for (int i = 0; i < kFrames; ++i) {
      const ros::Time stamp(test::kSceneStart + test::kSceneStep * i);
      nav_msgs::Odometry odom;
      odom.header.stamp = stamp;
      odom.header.frame_id = "odom";
      odom.pose.pose = ToPoseMsg(odom_from_map * PlanarIsometry(drive.frames[i].base.Planar()));
      out.write("/robot/odom", stamp, odom);
      sensor_msgs::JointState joints;
      joints.header.stamp = stamp;
      joints.name = {"head_pan", "head_tilt"};
      joints.position = {drive.frames[i].pan, drive.frames[i].camera.tilt};
      out.write("/joint_states", stamp, joints);
      out.write("/camera/image_raw", stamp, test::ImageMsg(drive.images[i], stamp));
    }
  }
};

const BagRun& TheRun() {
  static const BagRun run;
  return run;
}

class RosBagReplay : public test_support::CliTest {
 protected:
  std::string Args(const fs::path& bag, const std::string& odom_topic, const fs::path& out) {
    const Pose3Dof start = TheRun().drive.frames[0].base.Planar();
    return "replay --input " + bag.string() + " --image-topic /camera/image_raw --odom-topic " +
           odom_topic + " --joint-states-topic /joint_states --pan-joint head_pan --tilt-joint " +
           "head_tilt --height " + std::to_string(test::kSceneHeight) + " --model " + kSource +
           "/models/hall.cao --camera " + kSource + "/tests/data/camera_wide.xml --prior " +
           std::to_string(start.x) + "," + std::to_string(start.y) + "," +
           std::to_string(RadToDeg(start.heading)) + " --no-overlay --out " + out.string() +
           " --out-bag " + (out.string() + ".bag");
  }

  void ExpectRejected(const fs::path& bag, const std::string& odom_topic,
                      const std::string& named) {
    const fs::path out = dir_ / "out";
    const test_support::CommandRun run = Linetrack(Args(bag, odom_topic, out));
    EXPECT_EQ(run.code, 2) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find(named), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out.string() + ".bag"));
    EXPECT_FALSE(fs::exists(out.string() + ".bag.part"));
  }
};

TEST_F(RosBagReplay, PosesCarryTheBagsStampsAndMatchTheTruth) {
  const BagRun& run = TheRun();
  const fs::path out = dir_ / "replay";
  const test_support::CommandRun result = Linetrack(Args(run.bag, "/robot/odom", out));
  ASSERT_EQ(result.code, 0) << result.err;
  const std::vector<StampedPose> poses = ReadTum((out / "poses.txt").string());
  EXPECT_GE(static_cast<int>(poses.size()), kFrames - kMaxFramesWithoutPose);
  for (const StampedPose& pose : poses) {
    const double index = (pose.t - test::kSceneStart) / test::kSceneStep;
    const int i = static_cast<int>(std::lround(index));
    ASSERT_NEAR(index, i, kStampTolS / test::kSceneStep) << "not a bag stamp: " << pose.t;
    const Eigen::Vector3d truth = run.drive.frames[i].cam_from_world.inverse().translation();
    EXPECT_LT((pose.world_from_cam.translation() - truth).norm(), kPositionTolM) << "frame " << i;
  }

  rosbag::Bag bag((out.string() + ".bag"), rosbag::bagmode::Read);
  int with_covariance = 0, transforms = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto pose = m.instantiate<geometry_msgs::PoseWithCovarianceStamped>()) {
      const int i = static_cast<int>(
          std::lround((pose->header.stamp.toSec() - test::kSceneStart) / test::kSceneStep));
      ASSERT_GE(i, 0);
      ASSERT_LT(i, kFrames);
      const Pose3Dof truth = run.drive.frames[i].base.Planar();
      const Pose3Dof got = PlanarOf(ToIsometry(pose->pose.pose));
      EXPECT_LT(std::hypot(got.x - truth.x, got.y - truth.y), kPositionTolM) << "frame " << i;
      EXPECT_LT(std::abs(RadToDeg(WrapAngle(got.heading - truth.heading))), kYawTolDeg);
      const Matrix6d covariance = ToMatrix6(pose->pose.covariance);
      if (covariance.allFinite() && (covariance.diagonal().array() > 0.0).all()) ++with_covariance;
    } else if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& t : tf->transforms)
        transforms += t.header.frame_id == "map" && t.child_frame_id == "odom";
    }
  }
  EXPECT_EQ(with_covariance, static_cast<int>(poses.size()));
  EXPECT_EQ(transforms, static_cast<int>(poses.size()));
}

TEST_F(RosBagReplay, BadBagsExitTwoWithOneLineAndWriteNothing) {
  const BagRun& run = TheRun();
  ExpectRejected(run.bag, "/wheel/odom", "/wheel/odom");      // missing topic
  ExpectRejected(run.bag, "/joint_states", "/joint_states");  // wrong message type
  ExpectRejected(dir_ / "absent.bag", "/robot/odom", "absent.bag");

  // Truncated: the first half of the file.
  const std::string bytes = test_support::ReadAll(run.bag);
  const fs::path truncated = dir_ / "truncated.bag";
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  ExpectRejected(truncated, "/robot/odom", "truncated.bag");

  // Unindexed: the header's index position zeroed, as a recorder killed before closing leaves it.
  std::string unindexed_bytes = bytes;
  const size_t field = unindexed_bytes.find("index_pos=");
  ASSERT_NE(field, std::string::npos);
  for (size_t k = 0; k < 8; ++k)
    unindexed_bytes[field + 10 + k] = '\0';
  const fs::path unindexed = dir_ / "unindexed.bag";
  std::ofstream(unindexed, std::ios::binary) << unindexed_bytes;
  ExpectRejected(unindexed, "/robot/odom", "unindexed.bag");
}

}  // namespace
}  // namespace linetrack::app

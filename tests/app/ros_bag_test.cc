// `linetrack replay --input RUN.bag`: a bag written here (rendered hall frames, the robot's
// odometry in its own odom frame, the pan-tilt head's joint states) is replayed from --prior; the
// poses carry the bag's stamps and match the truth, the integrity outputs are those of a video's
// replay (frames.csv columns, covariance.jsonl, the summary's block, poses.txt tracking only, no
// integrity failure against the truth), and --out-bag holds the tracking poses with their
// covariance (the truth within its 99.9% region) and map -> odom, the others apart. Bad bags
// (missing topic, wrong type, truncated, unindexed) exit 2 with one line and write nothing. The
// camera may come from the bag's camera_info instead of --camera, and sit on a calibrated head
// (--mount) whose angles are the bag's joint states.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_messages.h"
#include "models/trajectory_io.h"
#include "tests/app/calibrated_head.h"
#include "tests/app/ros_test_scene.h"
#include "tests/support/cli_test.h"
#include "tracking/head/head_pointing.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;
const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kCameraFile = kSource + "/tests/data/camera_wide.xml";

constexpr int kFrames = 20;
constexpr double kPanAmplitudeDeg = 10.0;
constexpr double kPositionTolM = 0.05;  // camera centre and base position vs truth
constexpr double kYawTolDeg = 1.0;
constexpr double kStampTolS = 1e-6;
constexpr int kMaxFramesWithoutPose = 3;
// The matcher's pose is confirmed over ReacquisitionCheck::confirm_frames frames before it is
// tracking; a few more may be degraded on the clutter.
constexpr int kMaxFramesNotTracking = kMaxFramesWithoutPose + 5 + 3;
// chi-square with 3 degrees of freedom at 0.999: the 99.9% region of the x, y, yaw covariance.
constexpr double kRegion999Chi2Dof3 = 16.266;
// The protection levels of this scene (the wide camera 2-8 m from the walls) are 0.04-0.15 m: the
// robot's alert limit is set above them, so that most poses are tracking.
constexpr const char* kAlertLimit = "0.3,2";

// A run written once per test process: its frames rendered with the camera placed by
// `place_camera` (RenderHallDrive's; null: the nominal mount at kSceneHeight on the pan axis).
// ctest runs each test in its own process, in parallel: the files are the process's own.
struct BagRun {
  test::RenderedDrive drive;
  fs::path bag, truth;

  BagRun(const std::string& name,
         const std::function<Eigen::Isometry3d(const SequenceFrame&)>& place_camera)
      : drive(test::RenderHallDrive(kFrames, DegToRad(kPanAmplitudeDeg), place_camera)),
        bag(OwnPath(name + ".bag")),
        truth(OwnPath(name + "_truth.txt")) {
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
      sensor_msgs::CameraInfo info = test::CameraInfoOf(ReadCameraXml(kCameraFile));
      info.header.stamp = stamp;
      out.write("/camera/camera_info", stamp, info);
    }
    std::vector<StampedPose> truth_poses;
    for (int i = 0; i < kFrames; ++i) {
      truth_poses.push_back(
          {test::kSceneStart + test::kSceneStep * i, drive.frames[i].cam_from_world.inverse()});
    }
    std::ofstream(truth) << FormatTum(truth_poses);
  }
  ~BagRun() {
    std::error_code ignored;
    fs::remove(bag, ignored);
    fs::remove(truth, ignored);
  }

  // test_output/<pid>_`file`.
  static fs::path OwnPath(const std::string& file) {
    return fs::path(LINETRACK_BINARY_DIR) / "test_output" / (std::to_string(getpid()) + "_" + file);
  }
};

const BagRun& TheRun() {
  static const BagRun run("ros_bag_run", nullptr);
  return run;
}

// The camera on test::CalibratedHead at the joint states' angles.
const BagRun& TheMountRun() {
  static const BagRun run("ros_bag_mount_run", [](const SequenceFrame& f) {
    return CamFromWorldOnHead(test::CalibratedHead(), f.base.Planar(), test::kCrossingHeightM,
                              f.pan, f.camera.tilt);
  });
  return run;
}

class RosBagReplay : public test_support::CliTest {
 protected:
  // The replay of `bag`; the camera from --camera unless `camera` names another source.
  // The camera on the head: --height (the nominal mount) unless `mount` is --mount's flag.
  std::string Args(const fs::path& bag, const std::string& odom_topic, const fs::path& out,
                   const std::string& camera = "--camera " + kCameraFile,
                   const std::string& mount = "") {
    // Both runs drive the same base poses.
    const Pose3Dof start = (mount.empty() ? TheRun() : TheMountRun()).drive.frames[0].base.Planar();
    const std::string head =
        mount.empty() ? "--height " + std::to_string(test::kSceneHeight) : mount;
    return "replay --input " + bag.string() + " --image-topic /camera/image_raw --odom-topic " +
           odom_topic + " --joint-states-topic /joint_states --pan-joint head_pan --tilt-joint " +
           "head_tilt " + head + " --model " + kSource + "/models/hall.cao " + camera +
           " --prior " + std::to_string(start.x) + "," + std::to_string(start.y) + "," +
           std::to_string(RadToDeg(start.heading)) + " --no-overlay --out " + out.string() +
           " --out-bag " + (out.string() + ".bag") + " --alert-limit " + kAlertLimit;
  }

  void ExpectRejected(const fs::path& bag, const std::string& odom_topic, const std::string& named,
                      const std::string& extra = "") {
    const fs::path out = dir_ / "out";
    const test_support::CommandRun run = Linetrack(Args(bag, odom_topic, out) + extra);
    EXPECT_EQ(run.code, 2) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find(named), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out.string() + ".bag"));
    EXPECT_FALSE(fs::exists(out.string() + ".bag.part"));
  }
};

int CountLines(const fs::path& path) {
  std::ifstream in(path);
  int lines = 0;
  for (std::string line; std::getline(in, line);)
    ++lines;
  return lines;
}

// The output bag: tracking poses near the truth within the 99.9% region of their covariance, one
// map -> odom with each, the others on the degraded topic with theirs. Returns the counts.
struct OutBagCounts {
  int tracking = 0, degraded = 0, transforms = 0;
};
OutBagCounts CheckOutBag(const fs::path& path, const test::RenderedDrive& drive) {
  OutBagCounts n;
  rosbag::Bag bag(path.string(), rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto pose = m.instantiate<geometry_msgs::PoseWithCovarianceStamped>()) {
      const int i = static_cast<int>(
          std::lround((pose->header.stamp.toSec() - test::kSceneStart) / test::kSceneStep));
      EXPECT_GE(i, 0);
      EXPECT_LT(i, kFrames);
      if (i < 0 || i >= kFrames) continue;
      const Pose3Dof truth = drive.frames[i].base.Planar();
      const Pose3Dof got = PlanarOf(ToIsometry(pose->pose.pose));
      const Eigen::Vector3d e(got.x - truth.x, got.y - truth.y,
                              WrapAngle(got.heading - truth.heading));
      const Matrix6d covariance = ToMatrix6(pose->pose.covariance);
      EXPECT_TRUE(covariance.allFinite()) << "frame " << i;
      if (m.getTopic() == "/linetrack/pose_degraded") {
        ++n.degraded;
        continue;
      }
      EXPECT_EQ(m.getTopic(), "/linetrack/pose");
      ++n.tracking;
      EXPECT_LT(e.head<2>().norm(), kPositionTolM) << "frame " << i;
      EXPECT_LT(std::abs(RadToDeg(e.z())), kYawTolDeg) << "frame " << i;
      const Eigen::Matrix3d planar = test::PlanarBlock(covariance);
      EXPECT_GT(planar.determinant(), 0.0) << "frame " << i;
      EXPECT_LT(e.dot(planar.ldlt().solve(e)), kRegion999Chi2Dof3) << "frame " << i;
    } else if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& t : tf->transforms)
        n.transforms += t.header.frame_id == "map" && t.child_frame_id == "odom";
    }
  }
  return n;
}

TEST_F(RosBagReplay, PosesCarryTheBagsStampsAndMatchTheTruth) {
  const BagRun& run = TheRun();
  const fs::path out = dir_ / "replay";
  const test_support::CommandRun result =
      Linetrack(Args(run.bag, "/robot/odom", out) + " --ground-truth " + run.truth.string());
  ASSERT_EQ(result.code, 0) << result.err;
  const std::vector<StampedPose> poses = ReadTum((out / "poses.txt").string());
  EXPECT_GE(static_cast<int>(poses.size()), kFrames - kMaxFramesNotTracking);
  for (const StampedPose& pose : poses) {
    const double index = (pose.t - test::kSceneStart) / test::kSceneStep;
    const int i = static_cast<int>(std::lround(index));
    ASSERT_NEAR(index, i, kStampTolS / test::kSceneStep) << "not a bag stamp: " << pose.t;
    const Eigen::Vector3d truth = run.drive.frames[i].cam_from_world.inverse().translation();
    EXPECT_LT((pose.world_from_cam.translation() - truth).norm(), kPositionTolM) << "frame " << i;
  }

  // The integrity outputs of a video's replay: poses.txt the tracking poses, covariance.jsonl a
  // line per frame, frames.csv's integrity columns, the summary's block, no integrity failure.
  const nlohmann::json summary = nlohmann::json::parse(test_support::ReadAll(out / "summary.json"));
  const nlohmann::json& integrity = summary["integrity"];
  const int tracking = integrity["status_counts"]["tracking"].get<int>();
  const int degraded = integrity["status_counts"]["degraded"].get<int>();
  EXPECT_EQ(static_cast<int>(poses.size()), tracking);
  EXPECT_EQ(CountLines(out / "covariance.jsonl"), kFrames);
  EXPECT_EQ(CountLines(out / "frames.csv"), 1 + kFrames);
  EXPECT_EQ(integrity["ground_truth"]["integrity_failures"].get<int>(), 0);
  EXPECT_GT(integrity["sigma_x_m"]["p50"].get<double>(), 0.0);
  std::ifstream csv(out / "frames.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",state,sigma_x_m,sigma_y_m,sigma_heading_deg,protection_level_m,"
                        "protection_level_deg,"),
            std::string::npos)
      << header;

  const OutBagCounts n = CheckOutBag(out.string() + ".bag", run.drive);
  EXPECT_EQ(n.tracking, tracking);
  EXPECT_EQ(n.degraded, degraded);
  EXPECT_EQ(n.transforms, tracking);
}

// poses.txt of a replay: most frames tracked, each pose at a frame's stamp with the camera centre
// near that frame's truth.
void ExpectCameraCentresNearTheTruth(const std::vector<StampedPose>& poses,
                                     const test::RenderedDrive& drive) {
  EXPECT_GE(static_cast<int>(poses.size()), kFrames - kMaxFramesNotTracking);
  for (const StampedPose& pose : poses) {
    const int i = static_cast<int>(std::lround((pose.t - test::kSceneStart) / test::kSceneStep));
    ASSERT_GE(i, 0);
    ASSERT_LT(i, kFrames);
    const Eigen::Vector3d truth = drive.frames[i].cam_from_world.inverse().translation();
    EXPECT_LT((pose.world_from_cam.translation() - truth).norm(), kPositionTolM) << "frame " << i;
  }
}

// The camera from the bag's camera_info (no --camera): the same poses within the tolerances.
TEST_F(RosBagReplay, TheCameraFromTheBagsCameraInfo) {
  const BagRun& run = TheRun();
  const fs::path out = dir_ / "replay_info";
  const test_support::CommandRun result =
      Linetrack(Args(run.bag, "/robot/odom", out, "--camera-info-topic /camera/camera_info"));
  ASSERT_EQ(result.code, 0) << result.err;
  const std::vector<StampedPose> poses = ReadTum((out / "poses.txt").string());
  ExpectCameraCentresNearTheTruth(poses, run.drive);
}

// The camera on a calibrated head (--mount, its floor height in place of --height) at the bag's
// joint states: the output bag's base poses and the camera centres match the truth as with the
// nominal mount. The nominal geometry would put the camera 76.5 mm and 1.2 degrees off.
TEST_F(RosBagReplay, TheCameraOnACalibratedMountAtTheJointStates) {
  const BagRun& run = TheMountRun();
  const std::string mount =
      test::WriteMountJson(test::CalibratedHead(), kCameraFile, dir_ / "head");
  const fs::path out = dir_ / "replay_mount";
  const test_support::CommandRun result =
      Linetrack(Args(run.bag, "/robot/odom", out, "--camera " + kCameraFile, "--mount " + mount) +
                " --ground-truth " + run.truth.string());
  ASSERT_EQ(result.code, 0) << result.err;
  const std::vector<StampedPose> poses = ReadTum((out / "poses.txt").string());
  ExpectCameraCentresNearTheTruth(poses, run.drive);
  const OutBagCounts n = CheckOutBag(out.string() + ".bag", run.drive);
  EXPECT_EQ(n.tracking, static_cast<int>(poses.size()));
  EXPECT_GT(n.tracking, 0);

  // Without the joint states the head's angles are unknown: refused, naming what is missing.
  const test_support::CommandRun no_joints = Linetrack(
      "replay --input " + run.bag.string() + " --image-topic /camera/image_raw --odom-topic " +
      "/robot/odom --mount " + mount + " --tilt 5 --model " + kSource + "/models/hall.cao " +
      "--camera " + kCameraFile + " --prior 0,0,0 --no-overlay --out " + (dir_ / "nj").string());
  EXPECT_EQ(no_joints.code, 2) << no_joints.err;
  EXPECT_NE(no_joints.err.find("--joint-states-topic"), std::string::npos) << no_joints.err;
  EXPECT_FALSE(fs::exists(dir_ / "nj"));
}

TEST_F(RosBagReplay, BadBagsExitTwoWithOneLineAndWriteNothing) {
  const BagRun& run = TheRun();
  ExpectRejected(run.bag, "/wheel/odom", "/wheel/odom");      // missing topic
  ExpectRejected(run.bag, "/joint_states", "/joint_states");  // wrong message type
  ExpectRejected(dir_ / "absent.bag", "/robot/odom", "absent.bag");
  ExpectRejected(run.bag, "/robot/odom", "mount.json",
                 " --mount " + (dir_ / "mount.json").string());  // missing

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

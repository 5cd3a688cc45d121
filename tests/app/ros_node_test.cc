// `linetrack ros` against a real roscore (started here on a free port of 127.0.0.1): rendered
// frames of the bundled hall with the robot's odometry (its odom frame where the robot started,
// as on a real robot) and an initial pose off the truth as RViz sends it; the poses must come
// back stamped with the images' stamps, near the truth, with the integrity monitor's covariance:
// on ~pose only tracking poses, the truth within the 99.9% region of their covariance, the
// others on ~pose_degraded; map -> odom on /tf; the status must reach "tracking"; global
// localisation answers with an error.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>

#include <cstring>
#include <mutex>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_master.h"
#include "app/ros/ros_messages.h"
#include "tests/app/ros_test_scene.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;
const std::string kSource = LINETRACK_SOURCE_DIR;

constexpr int kFrames = 24;  // 2.4 s at 10 frames/s
constexpr double kHeight = test::kSceneHeight;
constexpr double kTiltDeg = test::kSceneTiltDeg;
constexpr double kPositionTolM = 0.05;  // base position vs truth
constexpr double kYawTolDeg = 1.0;
constexpr double kOdomTolM = 0.05;        // map -> odom vs the true odom frame
constexpr int kMaxFramesWithoutPose = 3;  // the matcher's first frames
// The matcher's pose is confirmed over ReacquisitionCheck::confirm_frames frames before it is
// tracking (on ~pose); a few more may be degraded on the clutter.
constexpr int kMaxFramesNotTracking = kMaxFramesWithoutPose + 5 + 3;
// chi-square with 3 degrees of freedom at 0.999: the 99.9% region of the x, y, yaw covariance.
constexpr double kRegion999Chi2Dof3 = 16.266;
// The protection levels of this scene (the wide camera 2-8 m from the walls) are 0.04-0.15 m: the
// robot's alert limit is set above them, so that most poses are tracking.
constexpr const char* kAlertLimit = "0.3,2";
constexpr double kDeadlineS = 60.0;  // any one wait (sanitizer builds are slow)

// What the test hears from the node.
struct Heard {
  std::mutex mutex;
  std::vector<geometry_msgs::PoseWithCovarianceStamped> poses, degraded;
  std::vector<geometry_msgs::TransformStamped> map_to_odom;
  std::vector<std::string> statuses;

  size_t StatusCount() {
    std::lock_guard<std::mutex> lock(mutex);
    return statuses.size();
  }
};

// The index of the image stamped `stamp`, or -1.
int FrameOf(const std::vector<ros::Time>& stamps, const ros::Time& stamp) {
  const auto it = std::find(stamps.begin(), stamps.end(), stamp);
  return it == stamps.end() ? -1 : static_cast<int>(it - stamps.begin());
}

// (x, y, yaw) of the published base pose minus the truth's.
Eigen::Vector3d PlanarError(const geometry_msgs::PoseWithCovarianceStamped& pose,
                            const Pose3Dof& truth) {
  const Pose3Dof got = PlanarOf(ToIsometry(pose.pose.pose));
  return {got.x - truth.x, got.y - truth.y, WrapAngle(got.heading - truth.heading)};
}

void ExpectNearTruth(const geometry_msgs::PoseWithCovarianceStamped& pose, const Pose3Dof& truth,
                     int frame) {
  const Eigen::Vector3d e = PlanarError(pose, truth);
  EXPECT_EQ(pose.header.frame_id, "map");
  EXPECT_LT(e.head<2>().norm(), kPositionTolM) << "frame " << frame;
  EXPECT_LT(std::abs(RadToDeg(e.z())), kYawTolDeg) << "frame " << frame;
}

TEST(RosNode, TracksRenderedFramesWithOdometryAndAnInitialPose) {
  const test::RenderedDrive hall = test::RenderHallDrive(kFrames, 0.0);
  const RosCore core(fs::temp_directory_path() / ("linetrack_ros_" + std::to_string(getpid())));
  ASSERT_TRUE(core.ready()) << "roscore did not start";
  ChildProcess node({LINETRACK_EXE, "ros", "--model", kSource + "/models/hall.cao", "--camera",
                     kSource + "/tests/data/camera_wide.xml", "--height", std::to_string(kHeight),
                     "--tilt", std::to_string(kTiltDeg), "--alert-limit", kAlertLimit,
                     "image:=/camera/image_raw", "odom:=/robot/odom"});
  ASSERT_TRUE(node.started());

  ros::M_string remappings;
  ros::init(remappings, "linetrack_ros_test", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  Heard heard;
  ros::Subscriber pose_sub = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      "/linetrack/pose", 100, [&](const geometry_msgs::PoseWithCovarianceStampedConstPtr& m) {
        std::lock_guard<std::mutex> lock(heard.mutex);
        heard.poses.push_back(*m);
      });
  ros::Subscriber degraded_sub = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      "/linetrack/pose_degraded", 100,
      [&](const geometry_msgs::PoseWithCovarianceStampedConstPtr& m) {
        std::lock_guard<std::mutex> lock(heard.mutex);
        heard.degraded.push_back(*m);
      });
  ros::Subscriber tf_sub =
      nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const tf2_msgs::TFMessageConstPtr& m) {
        std::lock_guard<std::mutex> lock(heard.mutex);
        for (const geometry_msgs::TransformStamped& t : m->transforms) {
          if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
            heard.map_to_odom.push_back(t);
          }
          EXPECT_FALSE(t.header.frame_id == "map" && t.child_frame_id == "base_link");
        }
      });
  ros::Subscriber status_sub = nh.subscribe<std_msgs::String>(
      "/linetrack/status", 100, [&](const std_msgs::StringConstPtr& m) {
        std::lock_guard<std::mutex> lock(heard.mutex);
        heard.statuses.push_back(m->data);
      });
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 2);
  ros::Publisher odom_pub = nh.advertise<nav_msgs::Odometry>("/robot/odom", 100);
  ros::Publisher initial_pub =
      nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("/initialpose", 1, true);
  ASSERT_TRUE(WaitFor(
      [&] {
        return image_pub.getNumSubscribers() > 0 && odom_pub.getNumSubscribers() > 0 &&
               initial_pub.getNumSubscribers() > 0 && pose_sub.getNumPublishers() > 0 &&
               degraded_sub.getNumPublishers() > 0 && status_sub.getNumPublishers() > 0 &&
               tf_sub.getNumPublishers() > 0;
      },
      kDeadlineS))
      << "the node did not connect";

  // The odometry frame is where the robot started; the initial pose is 0.3 m and 8 degrees off.
  const Eigen::Isometry3d odom_from_map = PlanarIsometry(hall.frames[0].base.Planar()).inverse();
  geometry_msgs::PoseWithCovarianceStamped initial;
  initial.header.frame_id = "map";
  initial.header.stamp = ros::Time(test::kSceneStart);
  const Pose3Dof start = hall.frames[0].base.Planar();
  initial.pose.pose =
      ToPoseMsg(PlanarIsometry({start.x + 0.25, start.y - 0.15, start.heading + DegToRad(8.0)}));
  initial.pose.covariance[0] = initial.pose.covariance[7] = 0.25;
  initial.pose.covariance[35] = 0.06853891945200942;
  initial_pub.publish(initial);

  std::vector<ros::Time> stamps;
  for (int i = 0; i < kFrames; ++i) {
    const ros::Time stamp(test::kSceneStart + test::kSceneStep * i);
    stamps.push_back(stamp);
    nav_msgs::Odometry odom;
    odom.header.stamp = stamp;
    odom.header.frame_id = "odom";
    odom.child_frame_id = "base_link";
    odom.pose.pose = ToPoseMsg(odom_from_map * PlanarIsometry(hall.frames[i].base.Planar()));
    odom_pub.publish(odom);
    const size_t before = heard.StatusCount();
    image_pub.publish(test::ImageMsg(hall.images[i], stamp));
    ASSERT_TRUE(WaitFor([&] { return heard.StatusCount() > before; }, kDeadlineS))
        << "no status for frame " << i;
  }
  ASSERT_TRUE(WaitFor([&] { return heard.StatusCount() >= kFrames; }, kDeadlineS));

  std_srvs::Empty empty;
  EXPECT_FALSE(ros::service::call("/linetrack/global_localization", empty))
      << "global localisation must answer with an error until it exists";

  std::lock_guard<std::mutex> lock(heard.mutex);
  ASSERT_EQ(static_cast<int>(heard.statuses.size()), kFrames);  // one per image, in order
  EXPECT_GE(static_cast<int>(heard.poses.size() + heard.degraded.size()),
            kFrames - kMaxFramesWithoutPose);
  std::string statuses;
  for (const std::string& status : heard.statuses)
    statuses += status + " ";
  EXPECT_GE(static_cast<int>(heard.poses.size()), kFrames - kMaxFramesNotTracking) << statuses;
  EXPECT_NE(std::find(heard.statuses.begin(), heard.statuses.end(), "tracking"),
            heard.statuses.end());
  for (const auto& pose : heard.poses) {
    const int i = FrameOf(stamps, pose.header.stamp);
    ASSERT_GE(i, 0) << "a pose stamped " << pose.header.stamp << ", not an image's";
    EXPECT_EQ(heard.statuses[i], "tracking") << "frame " << i << " on ~pose";
    ExpectNearTruth(pose, hall.frames[i].base.Planar(), i);
    // The truth within the 99.9% region of the published x, y, yaw covariance.
    const Matrix6d covariance = ToMatrix6(pose.pose.covariance);
    ASSERT_TRUE(covariance.allFinite());
    const Eigen::Matrix3d planar = test::PlanarBlock(covariance);
    ASSERT_GT(planar.determinant(), 0.0) << "frame " << i;
    const Eigen::Vector3d e = PlanarError(pose, hall.frames[i].base.Planar());
    EXPECT_LT(e.dot(planar.ldlt().solve(e)), kRegion999Chi2Dof3) << "frame " << i;
  }
  for (const auto& pose : heard.degraded) {
    const int i = FrameOf(stamps, pose.header.stamp);
    ASSERT_GE(i, 0) << "a degraded pose stamped " << pose.header.stamp << ", not an image's";
    EXPECT_TRUE(heard.statuses[i] == "degraded" || heard.statuses[i] == "relocalising")
        << "frame " << i << " on ~pose_degraded is " << heard.statuses[i];
    EXPECT_TRUE(ToMatrix6(pose.pose.covariance).allFinite());
  }
  ASSERT_FALSE(heard.map_to_odom.empty()) << "no map -> odom on /tf";
  const Eigen::Isometry3d map_from_odom = ToIsometry([&] {
    geometry_msgs::Pose p;
    const auto& t = heard.map_to_odom.back().transform;
    p.position.x = t.translation.x;
    p.position.y = t.translation.y;
    p.position.z = t.translation.z;
    p.orientation = t.rotation;
    return p;
  }());
  EXPECT_LT((map_from_odom.translation() - odom_from_map.inverse().translation()).norm(),
            kOdomTolM);
  spinner.stop();
  ros::shutdown();
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
}

}  // namespace
}  // namespace linetrack::app

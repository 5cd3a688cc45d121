// The fixture of the `linetrack ros` tests (ros_node_test.cc, ros_node_mount_test.cc): the node
// run against a roscore of its own on a free port, what it publishes heard, the rendered drive
// published with its odometry (and head angles), and the poses heard checked against the truth.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/String.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_master.h"
#include "app/ros/ros_messages.h"
#include "tests/app/ros_test_scene.h"

namespace linetrack::app::ros_node_test {

namespace fs = std::filesystem;
const std::string kSource = LINETRACK_SOURCE_DIR;
const std::string kCameraFile = kSource + "/tests/data/camera_wide.xml";

constexpr int kFrames = 24;  // 2.4 s at 10 frames/s
constexpr double kHeight = test::kSceneHeight;
constexpr double kTiltDeg = test::kSceneTiltDeg;
constexpr double kPositionTolM = 0.05;  // base position vs truth
constexpr double kYawTolDeg = 1.0;
constexpr double kOdomTolM = 0.05;        // map -> odom vs the true odom frame
constexpr int kMaxFramesWithoutPose = 3;  // the matcher's first frames
// A global answer is reported once confirmed (ReacquisitionCheck::confirm_frames).
constexpr int kGlobalConfirmFrames = 5;
// The matcher's pose is confirmed over ReacquisitionCheck::confirm_frames frames before it is
// tracking (on ~pose); a few more may be degraded on the clutter.
constexpr int kMaxFramesNotTracking = kMaxFramesWithoutPose + 5 + 3;
// chi-square with 3 degrees of freedom at 0.999: the 99.9% region of the x, y, yaw covariance.
constexpr double kRegion999Chi2Dof3 = 16.266;
// The protection levels of this scene (the wide camera 2-8 m from the walls) are 0.04-0.15 m: the
// robot's alert limit is set above them, so that most poses are tracking.
constexpr const char* kAlertLimit = "0.3,2";
constexpr double kDeadlineS = 60.0;  // any one wait (sanitizer builds are slow)
// The TF and joint_states tests' head: panning +-15 degrees, 0.2 m ahead of and 0.05 m right of the
// base's origin.
constexpr double kTfPanAmplitudeDeg = 15.0;
constexpr double kTfOffsetXM = 0.2;
constexpr double kTfOffsetYM = -0.05;
const std::string kTfBaseFrame = "robot_base";  // ~base_frame

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
inline int FrameOf(const std::vector<ros::Time>& stamps, const ros::Time& stamp) {
  const auto it = std::find(stamps.begin(), stamps.end(), stamp);
  return it == stamps.end() ? -1 : static_cast<int>(it - stamps.begin());
}

// (x, y, yaw) of the published base pose minus the truth's.
inline Eigen::Vector3d PlanarError(const geometry_msgs::PoseWithCovarianceStamped& pose,
                                   const Pose3Dof& truth) {
  const Pose3Dof got = PlanarOf(ToIsometry(pose.pose.pose));
  return {got.x - truth.x, got.y - truth.y, WrapAngle(got.heading - truth.heading)};
}

inline void ExpectNearTruth(const geometry_msgs::PoseWithCovarianceStamped& pose,
                            const Pose3Dof& truth, int frame) {
  const Eigen::Vector3d e = PlanarError(pose, truth);
  EXPECT_EQ(pose.header.frame_id, "map");
  EXPECT_LT(e.head<2>().norm(), kPositionTolM) << "frame " << frame;
  EXPECT_LT(std::abs(RadToDeg(e.z())), kYawTolDeg) << "frame " << frame;
}

// `linetrack ros` in its own process against a roscore of the test's, the test's node subscribed
// to what it publishes and publishing what it hears. One per test suite (ros::init once per
// process; ctest runs each suite in its own).
class NodeUnderTest {
 public:
  explicit NodeUnderTest(const std::vector<std::string>& flags)
      : core_(fs::temp_directory_path() / ("linetrack_ros_" + std::to_string(getpid()))) {
    if (!core_.ready()) return;
    // --model, and the topics the test publishes on; the rest from `flags`.
    std::vector<std::string> argv = {LINETRACK_EXE,
                                     "ros",
                                     "--model",
                                     kSource + "/models/hall.cao",
                                     "--alert-limit",
                                     kAlertLimit,
                                     "image:=/camera/image_raw",
                                     "odom:=/robot/odom"};
    argv.insert(argv.end(), flags.begin(), flags.end());
    node_ = std::make_unique<ChildProcess>(argv);
    ros::M_string remappings;
    ros::init(remappings, "linetrack_ros_test", ros::init_options::NoSigintHandler);
    nh_ = std::make_unique<ros::NodeHandle>();
    spinner_ = std::make_unique<ros::AsyncSpinner>(1);
    spinner_->start();
    Subscribe();
    image_pub = nh_->advertise<sensor_msgs::Image>("/camera/image_raw", 2);
    odom_pub = nh_->advertise<nav_msgs::Odometry>("/robot/odom", 100);
    initial_pub = nh_->advertise<geometry_msgs::PoseWithCovarianceStamped>("/initialpose", 1, true);
    tf_pub = nh_->advertise<tf2_msgs::TFMessage>("/tf", 100);
    tf_static_pub = nh_->advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
  }

  bool started() const { return core_.ready() && node_ && node_->started(); }

  // True once the node has subscribed to the images, odometry and initial pose (and /tf_static
  // with `tf`) and advertised what the test listens to.
  bool Connected(bool tf) const {
    return WaitFor(
        [&] {
          return image_pub.getNumSubscribers() > 0 && odom_pub.getNumSubscribers() > 0 &&
                 initial_pub.getNumSubscribers() > 0 && pose_sub_.getNumPublishers() > 0 &&
                 degraded_sub_.getNumPublishers() > 0 && status_sub_.getNumPublishers() > 0 &&
                 tf_sub_.getNumPublishers() > 0 && (!tf || tf_static_pub.getNumSubscribers() > 0);
        },
        kDeadlineS);
  }

  // RViz's "2D Pose Estimate" 0.3 m and 8 degrees off `base`, with RViz's covariance.
  void PublishInitialPose(const Pose3Dof& base) {
    geometry_msgs::PoseWithCovarianceStamped initial;
    initial.header.frame_id = "map";
    initial.header.stamp = ros::Time(test::kSceneStart);
    initial.pose.pose =
        ToPoseMsg(PlanarIsometry({base.x + 0.25, base.y - 0.15, base.heading + DegToRad(8.0)}));
    initial.pose.covariance[0] = initial.pose.covariance[7] = 0.25;
    initial.pose.covariance[35] = 0.06853891945200942;
    initial_pub.publish(initial);
  }

  // Publishes each frame's odometry (the base `map_from_base` seen from `odom_from_map`; none
  // before frame `first_odometry`), what `before_image` adds, then its image, and waits for its
  // status. The images' stamps.
  std::vector<ros::Time> Drive(const test::RenderedDrive& drive,
                               const std::vector<Eigen::Isometry3d>& map_from_base,
                               const Eigen::Isometry3d& odom_from_map,
                               const std::function<void(int, const ros::Time&)>& before_image,
                               size_t first_odometry = 0) {
    std::vector<ros::Time> stamps;
    for (size_t i = 0; i < drive.images.size(); ++i) {
      const ros::Time stamp(test::kSceneStart + test::kSceneStep * i);
      stamps.push_back(stamp);
      nav_msgs::Odometry odom;
      odom.header.stamp = stamp;
      odom.header.frame_id = "odom";
      odom.child_frame_id = "base_link";
      odom.pose.pose = ToPoseMsg(odom_from_map * map_from_base[i]);
      if (i >= first_odometry) odom_pub.publish(odom);
      if (before_image) before_image(static_cast<int>(i), stamp);
      const size_t before = heard.StatusCount();
      image_pub.publish(test::ImageMsg(drive.images[i], stamp));
      EXPECT_TRUE(WaitFor([&] { return heard.StatusCount() > before; }, kDeadlineS))
          << "no status for frame " << i;
    }
    EXPECT_TRUE(WaitFor([&] { return heard.StatusCount() >= stamps.size(); }, kDeadlineS));
    return stamps;
  }

  // Stops the test's node, then the node under test: its exit status.
  int Stop() {
    spinner_->stop();
    ros::shutdown();
    return node_->Stop();
  }

  Heard heard;
  ros::Publisher image_pub, odom_pub, initial_pub, tf_pub, tf_static_pub;

 private:
  void Subscribe() {
    pose_sub_ = nh_->subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        "/linetrack/pose", 100, [this](const geometry_msgs::PoseWithCovarianceStampedConstPtr& m) {
          std::lock_guard<std::mutex> lock(heard.mutex);
          heard.poses.push_back(*m);
        });
    degraded_sub_ = nh_->subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        "/linetrack/pose_degraded", 100,
        [this](const geometry_msgs::PoseWithCovarianceStampedConstPtr& m) {
          std::lock_guard<std::mutex> lock(heard.mutex);
          heard.degraded.push_back(*m);
        });
    tf_sub_ = nh_->subscribe<tf2_msgs::TFMessage>(
        "/tf", 100, [this](const tf2_msgs::TFMessageConstPtr& m) {
          std::lock_guard<std::mutex> lock(heard.mutex);
          for (const geometry_msgs::TransformStamped& t : m->transforms) {
            if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
              heard.map_to_odom.push_back(t);
            }
            EXPECT_FALSE(t.header.frame_id == "map" && t.child_frame_id == "base_link");
          }
        });
    status_sub_ = nh_->subscribe<std_msgs::String>("/linetrack/status", 100,
                                                   [this](const std_msgs::StringConstPtr& m) {
                                                     std::lock_guard<std::mutex> lock(heard.mutex);
                                                     heard.statuses.push_back(m->data);
                                                   });
  }

  RosCore core_;
  std::unique_ptr<ChildProcess> node_;
  std::unique_ptr<ros::NodeHandle> nh_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
  ros::Subscriber pose_sub_, degraded_sub_, tf_sub_, status_sub_;
};

// Every pose heard against the truth of its frame: on ~pose only tracking ones, near the truth and
// within the 99.9% region of their covariance; on ~pose_degraded the others; map -> odom on /tf
// near the true odometry frame; the status reached tracking.
inline void ExpectPosesOfTheTruth(Heard& heard, const std::vector<ros::Time>& stamps,
                                  const std::vector<Eigen::Isometry3d>& map_from_base,
                                  const Eigen::Isometry3d& odom_from_map,
                                  int max_frames_without_pose = kMaxFramesWithoutPose) {
  const int frames = static_cast<int>(stamps.size());
  std::lock_guard<std::mutex> lock(heard.mutex);
  ASSERT_EQ(static_cast<int>(heard.statuses.size()), frames);  // one per image, in order
  EXPECT_GE(static_cast<int>(heard.poses.size() + heard.degraded.size()),
            frames - max_frames_without_pose);
  std::string statuses;
  for (const std::string& status : heard.statuses)
    statuses += status + " ";
  EXPECT_GE(static_cast<int>(heard.poses.size()), frames - kMaxFramesNotTracking) << statuses;
  EXPECT_NE(std::find(heard.statuses.begin(), heard.statuses.end(), "tracking"),
            heard.statuses.end());
  for (const auto& pose : heard.poses) {
    const int i = FrameOf(stamps, pose.header.stamp);
    ASSERT_GE(i, 0) << "a pose stamped " << pose.header.stamp << ", not an image's";
    EXPECT_EQ(heard.statuses[i], "tracking") << "frame " << i << " on ~pose";
    const Pose3Dof truth = PlanarOf(map_from_base[i]);
    ExpectNearTruth(pose, truth, i);
    // The truth within the 99.9% region of the published x, y, yaw covariance.
    const Matrix6d covariance = ToMatrix6(pose.pose.covariance);
    ASSERT_TRUE(covariance.allFinite());
    const Eigen::Matrix3d planar = test::PlanarBlock(covariance);
    ASSERT_GT(planar.determinant(), 0.0) << "frame " << i;
    const Eigen::Vector3d e = PlanarError(pose, truth);
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
  const Eigen::Isometry3d map_from_odom = ToIsometry(heard.map_to_odom.back().transform);
  EXPECT_LT((map_from_odom.translation() - odom_from_map.inverse().translation()).norm(),
            kOdomTolM);
}

// The base's planar poses in the map, one per frame of `drive`.
inline std::vector<Eigen::Isometry3d> PlanarMapFromBase(const test::RenderedDrive& drive) {
  std::vector<Eigen::Isometry3d> map_from_base;
  for (const SequenceFrame& frame : drive.frames)
    map_from_base.push_back(PlanarIsometry(frame.base.Planar()));
  return map_from_base;
}

// Drives `hall` through `node`, the head's angles on /robot/joints (head_pan, head_tilt) at each
// image's stamp, from RViz's initial pose near the first frame, and checks the poses heard
// against the truth.
inline void DriveWithJointStates(NodeUnderTest& node, const test::RenderedDrive& hall) {
  ros::NodeHandle nh;
  ros::Publisher joints_pub = nh.advertise<sensor_msgs::JointState>("/robot/joints", 100);
  ASSERT_TRUE(node.Connected(/*tf=*/false)) << "the node did not connect";
  ASSERT_TRUE(WaitFor([&] { return joints_pub.getNumSubscribers() > 0; }, kDeadlineS));
  const std::vector<Eigen::Isometry3d> map_from_base = PlanarMapFromBase(hall);
  const Eigen::Isometry3d odom_from_map = map_from_base[0].inverse();
  node.PublishInitialPose(hall.frames[0].base.Planar());
  const std::vector<ros::Time> stamps =
      node.Drive(hall, map_from_base, odom_from_map, [&](int i, const ros::Time& stamp) {
        sensor_msgs::JointState joints;
        joints.header.stamp = stamp;
        joints.name = {"head_pan", "head_tilt"};
        joints.position = {hall.frames[i].pan, hall.frames[i].camera.tilt};
        joints_pub.publish(joints);
      });
  ExpectPosesOfTheTruth(node.heard, stamps, map_from_base, odom_from_map);
}

}  // namespace linetrack::app::ros_node_test

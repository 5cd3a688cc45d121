// `linetrack ros` against a real roscore (started here on a free port of 127.0.0.1): rendered
// frames of the bundled hall with the robot's odometry (its odom frame where the robot started,
// as on a real robot) and an initial pose off the truth as RViz sends it; the poses must come
// back stamped with the images' stamps, near the truth, with the integrity monitor's covariance:
// on ~pose only tracking poses, the truth within the 99.9% region of their covariance, the
// others on ~pose_degraded; map -> odom on /tf; the status must reach "tracking"; overlays and
// diagnostics come out. ~global_localization with no initial pose: the global mode finds the
// robot, and the poses are checked alike. Then the same with the
// head's angles and offset from TF base -> camera (static and dynamic transforms) instead of
// --height and --tilt, and with them from joint_states and the camera from camera_info; with
// joint_states and a calibrated mount (mount.json) of a camera off the nominal geometry.
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
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_master.h"
#include "app/ros/ros_messages.h"
#include "calibration/mount_file.h"
#include "models/pan_tilt.h"
#include "tests/app/ros_test_scene.h"
#include "tracking/head/head_pointing.h"

namespace linetrack::app {
namespace {

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
void ExpectPosesOfTheTruth(Heard& heard, const std::vector<ros::Time>& stamps,
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
std::vector<Eigen::Isometry3d> PlanarMapFromBase(const test::RenderedDrive& drive) {
  std::vector<Eigen::Isometry3d> map_from_base;
  for (const SequenceFrame& frame : drive.frames)
    map_from_base.push_back(PlanarIsometry(frame.base.Planar()));
  return map_from_base;
}

// The overlays and the diagnostics the node publishes.
struct HeardExtras {
  std::mutex mutex;
  std::vector<sensor_msgs::Image> overlays;  // headers and sizes only
  long images_received = -1;                 // the last diagnostics' count
  std::string hardware_id;
};

TEST(RosNode, TracksRenderedFramesWithOdometryAndAnInitialPose) {
  const test::RenderedDrive hall = test::RenderHallDrive(kFrames, 0.0);
  NodeUnderTest node({"--camera", kCameraFile, "--height", std::to_string(kHeight), "--tilt",
                      std::to_string(kTiltDeg)});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  ros::NodeHandle nh;
  HeardExtras extras;
  ros::Subscriber overlay_sub = nh.subscribe<sensor_msgs::Image>(
      "/linetrack/overlay", 100, [&](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(extras.mutex);
        extras.overlays.push_back(*m);
        extras.overlays.back().data.clear();
      });
  ros::Subscriber diagnostics_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(extras.mutex);
        for (const diagnostic_msgs::DiagnosticStatus& status : m->status) {
          for (const diagnostic_msgs::KeyValue& value : status.values) {
            if (value.key != "images received") continue;
            extras.images_received = std::stol(value.value);
            extras.hardware_id = status.hardware_id;
          }
        }
      });
  ASSERT_TRUE(node.Connected(/*tf=*/false)) << "the node did not connect";
  ASSERT_TRUE(WaitFor([&] { return overlay_sub.getNumPublishers() > 0; }, kDeadlineS));

  // The odometry frame is where the robot started.
  const std::vector<Eigen::Isometry3d> map_from_base = PlanarMapFromBase(hall);
  const Eigen::Isometry3d odom_from_map = map_from_base[0].inverse();
  node.PublishInitialPose(hall.frames[0].base.Planar());
  // The odometry starts one image late (an odometry node slower to start than the camera's): the
  // initial pose, applied at the first image without a reading, is anchored at the first one.
  const std::vector<ros::Time> stamps =
      node.Drive(hall, map_from_base, odom_from_map, nullptr, /*first_odometry=*/1);
  ExpectPosesOfTheTruth(node.heard, stamps, map_from_base, odom_from_map);

  // Overlays stamped with their images, up to the last, at the camera's size; diagnostics counting
  // the images.
  const auto overlays_done = [&] {
    std::lock_guard<std::mutex> lock(extras.mutex);
    return !extras.overlays.empty() && extras.overlays.back().header.stamp == stamps.back();
  };
  EXPECT_TRUE(WaitFor(overlays_done, kDeadlineS));
  const auto diagnostics_done = [&] {
    std::lock_guard<std::mutex> lock(extras.mutex);
    return extras.images_received == kFrames;
  };
  EXPECT_TRUE(WaitFor(diagnostics_done, kDeadlineS)) << "no diagnostics counting the images";
  {
    std::lock_guard<std::mutex> lock(extras.mutex);
    EXPECT_EQ(extras.hardware_id, "linetrack");
    for (const sensor_msgs::Image& overlay : extras.overlays) {
      const int i = FrameOf(stamps, overlay.header.stamp);
      ASSERT_GE(i, 0) << "an overlay stamped " << overlay.header.stamp << ", not an image's";
      EXPECT_EQ(overlay.encoding, "bgr8");
      EXPECT_EQ(overlay.width, hall.images[i].getWidth());
      EXPECT_EQ(overlay.height, hall.images[i].getHeight());
    }
  }
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
}

// The head's angles from TF instead of joint_states, without --height and --tilt: the camera 0.2 m
// ahead of and 0.05 m right of the base's origin (static robot_base -> head on /tf_static), panning
// (head -> camera_optical on /tf at each image's stamp). The base's truth is the rendered camera
// moved back by that mount, so that a mount taken wrongly (the offset, a stale pan) misses it.
// ~global_localization drops the prior: with no initial pose (the odometry frame is not the
// map's), the global mode finds the robot on the first frames, its pose is confirmed before it is
// tracking, and every pose is checked as with an initial pose.
TEST(RosNode, GlobalLocalizationFindsTheRobotWithNoInitialPose) {
  const test::RenderedDrive hall = test::RenderHallDrive(kFrames, 0.0);
  NodeUnderTest node({"--camera", kCameraFile, "--height", std::to_string(kHeight), "--tilt",
                      std::to_string(kTiltDeg)});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  ASSERT_TRUE(node.Connected(/*tf=*/false)) << "the node did not connect";
  const std::string service = "/linetrack/global_localization";
  ASSERT_TRUE(ros::service::waitForService(service, ros::Duration(kDeadlineS)));
  std_srvs::Empty empty;
  EXPECT_TRUE(ros::service::call(service, empty));
  const std::vector<Eigen::Isometry3d> map_from_base = PlanarMapFromBase(hall);
  const Eigen::Isometry3d odom_from_map = map_from_base[0].inverse();
  const std::vector<ros::Time> stamps = node.Drive(hall, map_from_base, odom_from_map, nullptr);
  {
    std::lock_guard<std::mutex> lock(node.heard.mutex);
    ASSERT_FALSE(node.heard.statuses.empty());
    EXPECT_NE(node.heard.statuses[0], "tracking") << "a global pose must be confirmed first";
  }
  ExpectPosesOfTheTruth(node.heard, stamps, map_from_base, odom_from_map,
                        kMaxFramesWithoutPose + kGlobalConfirmFrames);
}

TEST(RosNodeTf, TakesTheHeadFromTfAtTheImageStamp) {
  const test::RenderedDrive hall = test::RenderHallDrive(kFrames, DegToRad(kTfPanAmplitudeDeg));
  // A generous wait for TF to reach each image's stamp: it comes on another connection. The
  // base's frame is a private parameter (`_name:=` sets it on the parameter server), and the
  // command line's --head wins over the parameter server's ~head.
  NodeUnderTest node({"--camera", kCameraFile, "--odom-wait", "1", "_base_frame:=" + kTfBaseFrame,
                      "_head:=fixed", "--head", "tf"});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  ASSERT_TRUE(node.Connected(/*tf=*/true)) << "the node did not connect";

  geometry_msgs::TransformStamped base_to_head;
  base_to_head.header.frame_id = kTfBaseFrame;
  base_to_head.child_frame_id = "head";
  base_to_head.transform.translation.x = kTfOffsetXM;
  base_to_head.transform.translation.y = kTfOffsetYM;
  base_to_head.transform.translation.z = kHeight;
  base_to_head.transform.rotation.w = 1.0;
  tf2_msgs::TFMessage static_tf;
  static_tf.transforms.push_back(base_to_head);
  node.tf_static_pub.publish(static_tf);

  std::vector<CameraMount> mounts;
  std::vector<Eigen::Isometry3d> map_from_base;
  for (const SequenceFrame& frame : hall.frames) {
    mounts.push_back(
        {frame.camera.height, frame.pan, frame.camera.tilt, kTfOffsetXM, kTfOffsetYM, 0.0});
    map_from_base.push_back(frame.cam_from_world.inverse() *
                            BaseFromCamera(mounts.back()).inverse());
  }
  const Eigen::Isometry3d odom_from_map = map_from_base[0].inverse();
  node.PublishInitialPose(PlanarOf(map_from_base[0]));
  const std::vector<ros::Time> stamps =
      node.Drive(hall, map_from_base, odom_from_map, [&](int i, const ros::Time& stamp) {
        geometry_msgs::TransformStamped head_to_camera;
        head_to_camera.header.stamp = stamp;
        head_to_camera.header.frame_id = "head";
        head_to_camera.child_frame_id = "camera_optical";  // the images' frame_id
        Eigen::Isometry3d rotation = BaseFromCamera(mounts[i]);
        rotation.translation().setZero();
        head_to_camera.transform = ToTransformMsg(rotation);
        tf2_msgs::TFMessage tf;
        tf.transforms.push_back(head_to_camera);
        node.tf_pub.publish(tf);
      });
  ExpectPosesOfTheTruth(node.heard, stamps, map_from_base, odom_from_map);
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
}

// Drives `hall` through `node`, the head's angles on /robot/joints (head_pan, head_tilt) at each
// image's stamp, from RViz's initial pose near the first frame, and checks the poses heard
// against the truth.
void DriveWithJointStates(NodeUnderTest& node, const test::RenderedDrive& hall) {
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

// The head's angles from joint_states (the pan and tilt joints named on the command line), the
// head panning +-15 degrees: each image takes the angles at its stamp. The camera from
// camera_info (no --camera).
TEST(RosNodeJoints, TakesTheHeadFromJointStatesAtTheImageStamp) {
  const test::RenderedDrive hall = test::RenderHallDrive(kFrames, DegToRad(kTfPanAmplitudeDeg));
  NodeUnderTest node({"--odom-wait", "1", "--height", std::to_string(kHeight), "--pan-joint",
                      "head_pan", "--tilt-joint", "head_tilt", "joint_states:=/robot/joints",
                      "camera_info:=/camera/camera_info"});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  ros::NodeHandle nh;
  ros::Publisher info_pub =
      nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 1, /*latch=*/true);
  info_pub.publish(test::CameraInfoOf(ReadCameraXml(kCameraFile)));
  ASSERT_TRUE(WaitFor([&] { return info_pub.getNumSubscribers() > 0; }, kDeadlineS));
  DriveWithJointStates(node, hall);
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
}

// The mount test's head: the camera 76.5 mm left of and 68 mm above the axes' crossing (ViSP's
// PTU-46) but turned 1.2 degrees in yaw and 1 degree in pitch off the tilt frame's axes, on a base
// tilted 0.5 degrees in pitch and -0.3 in roll; the crossing 1.232 m above the floor.
constexpr double kMountYawDeg = 1.2;
constexpr double kMountPitchDeg = 1.0;
constexpr double kBasePitchDeg = 0.5;
constexpr double kBaseRollDeg = -0.3;
constexpr double kCrossingHeightM = kHeight - 0.068;

HeadGeometry CalibratedHead() {
  HeadGeometry head;
  head.tilt_from_camera = AlignedMount(Eigen::Vector3d(0.0, 0.0765, 0.068), CameraRoll::kUpright);
  head.tilt_from_camera.linear() =
      (Eigen::AngleAxisd(DegToRad(kMountYawDeg), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(DegToRad(kMountPitchDeg), Eigen::Vector3d::UnitY()))
          .toRotationMatrix() *
      head.tilt_from_camera.linear();
  head.level_from_base = LevelFromBaseRotation(DegToRad(kBaseRollDeg), DegToRad(kBasePitchDeg));
  return head;
}

// mount.json of `head` as calibrate-mount writes it, with a floor calibration (the crossing's
// height and the base's tilt), in `dir`.
std::string WriteMountJson(const HeadGeometry& head, const fs::path& dir) {
  MountCalibration calibration;
  calibration.status = MountStatus::kOk;
  calibration.tilt_from_camera = head.tilt_from_camera;
  calibration.covariance.diagonal().setConstant(1e-8);
  MountRunInfo info;
  info.camera_path = kCameraFile;
  FloorCalibration floor;
  floor.ok = true;
  floor.floor = {kCrossingHeightM, DegToRad(kBaseRollDeg), DegToRad(kBasePitchDeg)};
  info.floor = floor;
  fs::create_directories(dir);
  const std::string path = (dir / "mount.json").string();
  std::ofstream(path) << MountJson(calibration, info);
  return path;
}

// The head's angles from joint_states and the camera's calibrated mount on the head from --mount
// (its floor height in place of --height): the frames rendered with the camera on that head, the
// base poses must come back as in the joints test. The nominal geometry would put the camera 76.5
// mm and 1.2 degrees off the truth.
TEST(RosNodeMount, TakesTheCalibratedMountWithTheJointStates) {
  const HeadGeometry head = CalibratedHead();
  const test::RenderedDrive hall =
      test::RenderHallDrive(kFrames, DegToRad(kTfPanAmplitudeDeg), [&](const SequenceFrame& f) {
        return CamFromWorldOnHead(head, f.base.Planar(), kCrossingHeightM, f.pan, f.camera.tilt);
      });
  const fs::path dir =
      fs::temp_directory_path() / ("linetrack_ros_mount_" + std::to_string(getpid()));
  const std::string mount = WriteMountJson(head, dir);
  NodeUnderTest node({"--odom-wait", "1", "--mount", mount, "--pan-joint", "head_pan",
                      "--tilt-joint", "head_tilt", "joint_states:=/robot/joints", "--camera",
                      kCameraFile});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  DriveWithJointStates(node, hall);
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
  fs::remove_all(dir);
}

// What `linetrack ros` with `flags` did against the running master, once it exited.
struct Refusal {
  int exit_code = -1;   // -1: killed, or still running at the deadline
  std::string stderr_;  // its whole stderr
};

// Runs `linetrack ros --model hall.cao --camera camera_wide.xml FLAGS` through the shell, its
// stderr to `dir`/stderr.txt.
Refusal RunRefused(const std::vector<std::string>& flags, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  std::string command = std::string("exec '") + LINETRACK_EXE + "' ros --model '" + kSource +
                        "/models/hall.cao' --camera '" + kCameraFile + "'";
  for (const std::string& flag : flags)
    command += " '" + flag + "'";
  command += " 2> '" + err.string() + "'";
  ChildProcess node({"sh", "-c", command});
  Refusal r;
  if (!WaitFor([&] { return !node.Running(); }, kDeadlineS)) return r;
  const int status = node.Stop();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  std::ifstream in(err);
  r.stderr_.assign(std::istreambuf_iterator<char>(in), {});
  return r;
}

// One line on stderr, containing `what`, and exit 2.
void ExpectRefused(const Refusal& r, const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << r.stderr_;
  EXPECT_EQ(std::count(r.stderr_.begin(), r.stderr_.end(), '\n'), 1) << r.stderr_;
  EXPECT_NE(r.stderr_.find(what), std::string::npos) << r.stderr_;
}

// --mount with the head from TF or fixed, a mount file that is not one or is missing, and a mount
// without a floor height nor --height: one line on stderr naming the flag or the file, exit 2.
TEST(RosNodeMount, RefusesAMountItCannotUse) {
  const fs::path dir =
      fs::temp_directory_path() / ("linetrack_ros_bad_" + std::to_string(getpid()));
  RosCore core(dir / "ros");
  ASSERT_TRUE(core.ready()) << "roscore did not start";
  const std::string good = WriteMountJson(CalibratedHead(), dir);
  const std::string bad = (dir / "bad.json").string();
  std::ofstream(bad) << "{\"tilt_from_camera\": [1, 0, 0]}\n";
  std::ifstream in(good);
  nlohmann::json j = nlohmann::json::parse(in);
  j.erase("floor");
  const std::string no_floor = (dir / "no_floor.json").string();
  std::ofstream(no_floor) << j.dump();
  const std::string missing = (dir / "missing.json").string();
  const std::vector<std::string> joints = {"--pan-joint", "head_pan", "--tilt-joint", "head_tilt"};
  auto with_joints = [&](std::vector<std::string> flags) {
    flags.insert(flags.end(), joints.begin(), joints.end());
    return flags;
  };
  ExpectRefused(RunRefused({"--mount", good, "--head", "tf"}, dir), "--mount");
  ExpectRefused(
      RunRefused({"--mount", good, "--head", "fixed", "--height", "1.3", "--tilt", "5"}, dir),
      "--mount");
  ExpectRefused(RunRefused(with_joints({"--mount", bad}), dir), bad);
  ExpectRefused(RunRefused(with_joints({"--mount", missing}), dir), missing);
  ExpectRefused(RunRefused(with_joints({"--mount", no_floor}), dir), "--height");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace linetrack::app

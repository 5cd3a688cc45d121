// `linetrack ros` against a real roscore (started here on a free port of 127.0.0.1): rendered
// frames of the bundled hall with the robot's odometry (its odom frame where the robot started,
// as on a real robot) and an initial pose off the truth as RViz sends it; the poses must come
// back stamped with the images' stamps, near the truth, with the integrity monitor's covariance:
// on ~pose only tracking poses, the truth within the 99.9% region of their covariance, the
// others on ~pose_degraded; map -> odom on /tf; the status must reach "tracking"; overlays and
// diagnostics come out. ~global_localization with no initial pose: the global mode finds the
// robot, and the poses are checked alike. Then the same with the
// head's angles and offset from TF base -> camera (static and dynamic transforms) instead of
// --height and --tilt, and with them from joint_states and the camera from camera_info
// (the calibrated mount: ros_node_mount_test.cc).
#include "tests/app/ros_node_fixture.h"

namespace linetrack::app {
namespace {

using namespace ros_node_test;  // NOLINT: the fixture of these tests

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

}  // namespace
}  // namespace linetrack::app

// `linetrack bench ros`: the node's latency from an image's arrival to its pose published, beyond
// the tracking step, on a rendered drive through a model (the node in this process, a roscore of
// its own on a free port). Paced (the next image once the last is done) or at a fixed rate, where
// the images arriving during a tracking step are dropped, the oldest first.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <atomic>
#include <iomanip>
#include <iostream>
#include <thread>

#include "app/ros/ros_commands.h"
#include "app/ros/ros_master.h"
#include "app/ros/ros_messages.h"
#include "app/ros/ros_node.h"
#include "models/errors.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

struct BenchRosOptions {
  std::string model, camera, nav;
  int frames = 100;
  double rate = 0.0;  // images per second; 0: paced
  double height = 1.3, tilt_deg = 5.0;
  std::string head = "fixed";  // the node's ~head: fixed (--height, --tilt) or tf (base -> camera)
};

constexpr const char* kCameraFrame = "camera_optical";

struct Drive {
  std::vector<SequenceFrame> frames;
  std::vector<sensor_msgs::Image> images;
};

Drive RenderDrive(const BenchRosOptions& opt) {
  const WireframeModel model = WireframeModel::Load(opt.model);
  const CameraIntrinsics camera = LoadCamera(opt.camera);
  NavigableAreaOptions nav;
  nav.sidecar_path = opt.nav;
  const NavigableArea area = NavigableArea::FromModel(model, nav);
  DriveOptions drive;
  drive.frames = opt.frames;
  drive.height = opt.height;
  drive.tilt = DegToRad(opt.tilt_deg);
  Drive d;
  d.frames = DriveAlongLoop(LoopInsideArea(area), drive);
  SceneRenderer renderer(model, camera, RenderOptions(), &area);
  for (int i = 0; i < opt.frames; ++i) {
    const vpImage<unsigned char> image = renderer.Render(d.frames[i].cam_from_world, i);
    sensor_msgs::Image msg;
    msg.header.stamp = ros::Time(1.0 + d.frames[i].t);
    msg.header.frame_id = kCameraFrame;
    msg.width = image.getWidth();
    msg.height = image.getHeight();
    msg.encoding = "mono8";
    msg.step = msg.width;
    msg.data.assign(image.bitmap, image.bitmap + image.getSize());
    d.images.push_back(std::move(msg));
  }
  return d;
}

void PrintQuantiles(const char* what, const std::vector<double>& ms) {
  if (ms.empty()) return;
  std::cout << std::fixed << std::setprecision(2) << "  " << what << ": median "
            << QuantileNearestRank(ms, 0.5) << " ms, p95 " << QuantileNearestRank(ms, 0.95)
            << " ms, max " << *std::max_element(ms.begin(), ms.end()) << " ms\n";
}

int RunBenchRos(const BenchRosOptions& opt) {
  if (opt.frames < 2) throw InputError("--frames: at least 2");
  CheckRange(opt.rate, 0.0, 1000.0, "--rate");
  const Drive drive = RenderDrive(opt);
  const RosCore core(std::filesystem::temp_directory_path() /
                     ("linetrack_bench_ros_" + std::to_string(getpid())));
  if (!core.ready()) throw std::runtime_error("bench ros: roscore did not start");
  ros::M_string remappings;
  ros::init(remappings, "linetrack_bench", ros::init_options::NoSigintHandler);
  ros::NodeHandle nh, node_nh("linetrack");
  RosNodeOptions options;
  options.model = opt.model;
  options.camera = opt.camera;
  options.head = opt.head;
  if (opt.head == "fixed") {
    options.height = opt.height;
    options.tilt_deg = opt.tilt_deg;
  }
  ros::Publisher tf_static_pub = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
  if (opt.head == "tf") {  // the drive's mount, as a robot's URDF would give it
    CameraMount mount;
    mount.height = opt.height;
    mount.tilt = DegToRad(opt.tilt_deg);
    geometry_msgs::TransformStamped base_to_camera;
    base_to_camera.header.frame_id = options.base_frame;
    base_to_camera.child_frame_id = kCameraFrame;
    base_to_camera.transform = ToTransformMsg(BaseFromCamera(mount));
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(base_to_camera);
    tf_static_pub.publish(tf);
  }
  RosNode node(options, nh, node_nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  std::thread worker([&node] { node.Run(); });
  std::atomic<long> statuses{0};
  ros::Subscriber status_sub = nh.subscribe<std_msgs::String>(
      "/linetrack/status", 1000, [&](const std_msgs::StringConstPtr&) { ++statuses; });
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("image", 2);
  ros::Publisher odom_pub = nh.advertise<nav_msgs::Odometry>("odom", 1000);
  ros::Publisher initial_pub =
      nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("initialpose", 1, true);
  WaitFor(
      [&] {
        return status_sub.getNumPublishers() > 0 && image_pub.getNumSubscribers() > 0 &&
               (opt.head != "tf" || tf_static_pub.getNumSubscribers() > 0);
      },
      30.0);
  geometry_msgs::PoseWithCovarianceStamped initial;
  initial.header.frame_id = "map";
  initial.header.stamp = drive.images.front().header.stamp;
  initial.pose.pose = ToPoseMsg(PlanarIsometry(drive.frames.front().base.Planar()));
  initial.pose.covariance[0] = initial.pose.covariance[7] = 0.25;
  initial.pose.covariance[35] = 0.0685;
  initial_pub.publish(initial);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < opt.frames; ++i) {
    nav_msgs::Odometry odom;
    odom.header.stamp = drive.images[i].header.stamp;
    odom.pose.pose = ToPoseMsg(PlanarIsometry(drive.frames[i].base.Planar()));
    odom_pub.publish(odom);
    const long before = statuses;
    image_pub.publish(drive.images[i]);
    if (opt.rate > 0.0) {
      std::this_thread::sleep_until(
          start + std::chrono::microseconds(static_cast<long>((i + 1) * 1e6 / opt.rate)));
    } else {
      WaitFor([&] { return statuses > before; }, 60.0);
    }
  }
  const RosNodeStats stats = node.Stats();
  WaitFor([&] { return statuses >= stats.received - stats.dropped; }, 60.0);
  node.Stop();
  worker.join();
  spinner.stop();
  ros::shutdown();
  const RosNodeStats done = node.Stats();
  std::cout << "bench ros: " << done.received << " images ("
            << (opt.rate > 0.0 ? std::to_string(opt.rate) + " /s" : std::string("paced")) << "), "
            << done.dropped << " dropped, " << done.processed << " tracked, " << done.with_pose
            << " poses on ~pose, " << done.degraded << " on ~pose_degraded, " << done.no_mount
            << " without a camera mount (head " << opt.head << ")\n";
  PrintQuantiles("tracking step", done.track_ms);
  PrintQuantiles("taken to pose published, beyond the tracking step", done.overhead_ms);
  PrintQuantiles("waiting for the worker after arrival", done.wait_ms);
  return done.with_pose > 0 ? kExitOk : kExitJobFailed;
}

}  // namespace

void AddBenchRos(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchRosOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "ros",
      "Latency of `linetrack ros` from an image's arrival to its pose published, beyond the "
      "tracking step, on a rendered drive (roscore of its own on a free port)");
  cmd->add_option("--model", opt->model, "ViSP .cao model")->required();
  cmd->add_option("--camera", opt->camera, "Camera file: ViSP XML, OpenCV or ROS YAML")->required();
  cmd->add_option("--nav", opt->nav, "Navigable-area sidecar (.nav.json) for the drive");
  cmd->add_option("--frames", opt->frames, "Frames of the drive")->capture_default_str();
  cmd->add_option("--rate", opt->rate, "Images per second (0: the next once the last is done)")
      ->capture_default_str();
  cmd->add_option("--head", opt->head,
                  "The node's camera mount: fixed (--height, --tilt) or tf (a static TF "
                  "base_link -> camera_optical)")
      ->check(CLI::IsMember({"fixed", "tf"}))
      ->capture_default_str();
  cmd->callback([opt, action] { *action = [opt] { return RunBenchRos(*opt); }; });
}

}  // namespace linetrack::app

// `linetrack ros`: the command line of the node. ROS's own arguments (remappings such as
// image:=/cam/image_raw, __name:=, __ns:=) pass through to ros::init.
#include <ros/ros.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>
#include <thread>

#include "app/ros/ros_commands.h"
#include "app/ros/ros_node.h"
#include "models/errors.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

struct RosCommandOptions {
  RosNodeOptions node;
  std::vector<std::string> ros_args;  // name:=value
  std::vector<std::string> given;     // the flags given, as parameter names
};

int RunRos(RosCommandOptions opt) {
  ros::M_string remappings;
  for (const std::string& arg : opt.ros_args) {
    const size_t at = arg.find(":=");
    if (at == std::string::npos || at == 0) {
      throw InputError("ros: unexpected argument '" + arg + "' (ROS remappings are name:=value)");
    }
    remappings[arg.substr(0, at)] = arg.substr(at + 2);
  }
  ros::init(remappings, "linetrack", ros::init_options::NoSigintHandler);
  if (!ros::master::check()) {
    throw InputError("ros: no ROS master at " + ros::master::getURI() +
                     " (start roscore, or set ROS_MASTER_URI)");
  }
  ros::NodeHandle nh, private_nh("~");
  ReadRosParameters(private_nh, opt.given, &opt.node);
  StopSignals signals;
  RosNode node(opt.node, nh, private_nh);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  std::thread watcher([&node] {
    while (ros::ok() && StopSignals::Received() == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    node.Stop();
  });
  spdlog::info("ros: node {} running (model {})", ros::this_node::getName(), opt.node.model);
  node.Run();
  ros::shutdown();
  watcher.join();
  const RosNodeStats stats = node.Stats();
  std::cout << "ros: " << stats.received << " images, " << stats.dropped << " dropped, "
            << stats.processed << " tracked, " << stats.with_pose << " poses on ~pose, "
            << stats.degraded << " on ~pose_degraded, " << stats.no_mount
            << " without a camera mount";
  if (!stats.overhead_ms.empty()) {
    std::cout << "; beyond the tracking step median " << QuantileNearestRank(stats.overhead_ms, 0.5)
              << " ms, p95 " << QuantileNearestRank(stats.overhead_ms, 0.95)
              << " ms; waiting for the worker median " << QuantileNearestRank(stats.wait_ms, 0.5)
              << " ms";
  }
  std::cout << std::endl;
  return kExitOk;
}

}  // namespace

void AddRos(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<RosCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "ros",
      "ROS 1 node with AMCL's conventions: images, odometry, joint states or TF and initialpose "
      "in; "
      "~pose (PoseWithCovarianceStamped of the base in the map), map -> odom on /tf, ~status, "
      "diagnostics and ~overlay out (docs/ros.md). Flags override the parameters (~model, ...); "
      "remappings as name:=value");
  RosNodeOptions& o = opt->node;
  auto flag = [&](const char* name, const char* param, auto* value, const char* help) {
    cmd->add_option(name, *value, help)->each([opt, param](const std::string&) {
      opt->given.push_back(param);
    });
  };
  flag("--model", "model", &o.model, "ViSP .cao model (parameter ~model); its frame is the map");
  flag("--camera", "camera", &o.camera,
       "Camera file: ViSP XML, OpenCV or ROS YAML (~camera); default: camera_info");
  flag("--settings", "settings", &o.settings, "ViSP tracker XML (~settings)");
  flag("--map-frame", "map_frame", &o.map_frame, "Map frame (~map_frame, default map)");
  flag("--odom-frame", "odom_frame", &o.odom_frame, "Odometry frame (~odom_frame, default odom)");
  flag("--base-frame", "base_frame", &o.base_frame, "Base frame (~base_frame, default base_link)");
  flag("--camera-frame", "camera_frame", &o.camera_frame,
       "Camera frame for TF (~camera_frame, default the image header's frame_id)");
  flag("--head", "head", &o.head,
       "Head angles from: auto (joint_states when a joint is named, else TF base -> camera when "
       "TF links them, else --height/--tilt), joint_states, tf or fixed (~head, default auto)");
  flag("--height", "height", &o.height,
       "Camera height above the base's origin, metres, without TF; with --mount, taped with the "
       "head level, and optional when the mount file has a floor height (~height)");
  flag("--tilt", "tilt", &o.tilt_deg,
       "Camera tilt below the horizontal without a tilt joint or TF, degrees (~tilt)");
  flag("--pan-joint", "pan_joint", &o.pan_joint, "Pan joint in joint_states (~pan_joint)");
  flag("--tilt-joint", "tilt_joint", &o.tilt_joint, "Tilt joint in joint_states (~tilt_joint)");
  flag("--mount", "mount", &o.mount,
       "mount.json of calibrate-mount: the camera's calibrated mount on the head, with the "
       "joint_states angles, the axes' crossing at the base's origin (~mount)");
  flag("--alert-limit", "alert_limit", &o.integrity.alert_limit,
       "METRES,DEGREES: a pose is 'tracking' (on ~pose) only when its protection levels are "
       "within it, else 'degraded' (~pose_degraded) (~alert_limit, default 0.10,2)");
  flag("--camera-sigma", "camera_sigma", &o.integrity.camera_sigma,
       "Calibration uncertainty FOCAL_RELATIVE,PRINCIPAL_POINT_PX in the covariance "
       "(~camera_sigma, default 0.003,1)");
  flag("--model-sigma", "model_sigma", &o.integrity.model_sigma_m,
       "Model error allowance, metres at each edge end (~model_sigma)");
  flag("--kidnap-after-s", "kidnap_after_s", &o.global.kidnap_after_s,
       "Global mode (the robot may have been carried away) after this many seconds of frames "
       "(at least 2) that the matcher cannot place around the odometry's prior and the global "
       "mode places elsewhere (~kidnap_after_s, default 0.3; 0: off)");
  flag("--global-after-s", "global_after_s", &o.global.global_after_s,
       "Global mode after this many seconds lost (~global_after_s, default 2.5; 0: off)");
  flag("--global-after-m", "global_after_m", &o.global.global_after_m,
       "Global mode after this many metres driven while lost (~global_after_m, default 3; 0: "
       "off)");
  flag("--odom-wait", "odom_wait", &o.odom_wait,
       "Seconds an image waits for the odometry to reach its stamp (~odom_wait, default 0.05)");
  flag("--transform-tolerance", "transform_tolerance", &o.transform_tolerance,
       "Seconds added to the stamp of map -> odom, as AMCL (~transform_tolerance, default 0.1)");
  // Remappings are positional, so that unknown flags still reach the global ones (-q).
  cmd->add_option("remappings", opt->ros_args, "ROS remappings name:=value (__name, __log, ...)");
  cmd->callback([opt, action] { *action = [opt] { return RunRos(*opt); }; });
}

}  // namespace linetrack::app

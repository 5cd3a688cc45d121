#include "app/ros/ros_node.h"

#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/image_encodings.h>
#include <std_msgs/String.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/transform_broadcaster.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>

#include "app/cli_common.h"
#include "app/replay_output.h"
#include "app/ros/newest_only.h"
#include "app/ros/ros_messages.h"
#include "app/ros/ros_tracker.h"
#include "models/errors.h"
#include "models/occlusion.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxTimings = 100000;  // per-frame timings kept (a day at 1 frame/s)

bool Given(const std::vector<std::string>& given, const char* name) {
  return std::find(given.begin(), given.end(), name) != given.end();
}

template <typename T>
void Param(const ros::NodeHandle& nh, const std::vector<std::string>& given, const char* name,
           T* value) {
  if (!Given(given, name)) nh.getParam(name, *value);
}

}  // namespace

void RosNodeOptions::Check() const {
  if (model.empty()) throw InputError("ros: no model: give --model or the parameter ~model");
  MountOptions().Check();
  integrity.Options();  // throws naming the flag
  global.Options();
  CheckRange(transform_tolerance, 0.0, 10.0, "--transform-tolerance");
  CheckRange(odom_max_gap, 0.0, 10.0, "--odom-max-gap");
  CheckRange(odom_wait, 0.0, 1.0, "--odom-wait");
  for (const std::string* frame : {&map_frame, &odom_frame, &base_frame}) {
    if (frame->empty()) throw InputError("ros: frame names must not be empty");
  }
}

CameraMountSourceOptions RosNodeOptions::MountOptions() const {
  CameraMountSourceOptions o;
  o.head = ParseHeadSource(head);
  o.height = height;
  o.tilt = DegToRad(tilt_deg);
  o.pan_joint = pan_joint;
  o.tilt_joint = tilt_joint;
  o.mount = mount;
  o.base_frame = base_frame;
  o.camera_frame = camera_frame;
  o.wait = odom_wait;
  o.max_gap = odom_max_gap;
  return o;
}

void ReadRosParameters(const ros::NodeHandle& nh, const std::vector<std::string>& given,
                       RosNodeOptions* o) {
  Param(nh, given, "model", &o->model);
  Param(nh, given, "camera", &o->camera);
  Param(nh, given, "settings", &o->settings);
  Param(nh, given, "map_frame", &o->map_frame);
  Param(nh, given, "odom_frame", &o->odom_frame);
  Param(nh, given, "base_frame", &o->base_frame);
  Param(nh, given, "camera_frame", &o->camera_frame);
  Param(nh, given, "head", &o->head);
  Param(nh, given, "height", &o->height);
  Param(nh, given, "tilt", &o->tilt_deg);
  Param(nh, given, "pan_joint", &o->pan_joint);
  Param(nh, given, "tilt_joint", &o->tilt_joint);
  Param(nh, given, "mount", &o->mount);
  Param(nh, given, "transform_tolerance", &o->transform_tolerance);
  Param(nh, given, "odom_max_gap", &o->odom_max_gap);
  Param(nh, given, "odom_wait", &o->odom_wait);
  Param(nh, given, "alert_limit", &o->integrity.alert_limit);
  Param(nh, given, "camera_sigma", &o->integrity.camera_sigma);
  Param(nh, given, "model_sigma", &o->integrity.model_sigma_m);
  Param(nh, given, "kidnap_after_s", &o->global.kidnap_after_s);
  Param(nh, given, "global_after_s", &o->global.global_after_s);
  Param(nh, given, "global_after_m", &o->global.global_after_m);
}

struct RosNode::Impl {
  struct PendingImage {
    sensor_msgs::ImageConstPtr msg;
    Clock::time_point arrival;
  };
  struct PendingStart {
    Pose3Dof map_base;
    Matrix6d covariance;
    double t = 0.0;
  };

  RosNodeOptions options;
  ros::NodeHandle nh, pnh;
  image_transport::ImageTransport it, private_it;
  image_transport::Subscriber image_sub;
  image_transport::Publisher overlay_pub;
  ros::Subscriber info_sub, odom_sub, joints_sub, initial_sub;
  ros::Publisher pose_pub, degraded_pub, status_pub;
  ros::ServiceServer global_srv;
  tf2_ros::TransformBroadcaster tf;
  diagnostic_updater::Updater updater;

  RosTrackerOptions tracker_options;
  std::unique_ptr<RosTracker> tracker;  // worker thread only
  std::unique_ptr<OcclusionTester> occlusion;
  std::unique_ptr<CameraMountSource> mount_source;
  // From the last tracking pose (worker thread only); cleared by a new initial pose.
  std::optional<Eigen::Isometry3d> map_from_odom;

  mutable std::mutex mutex;  // guards everything below
  std::condition_variable wake;
  NewestOnly<PendingImage> pending;
  std::optional<CameraIntrinsics> camera_from_info;
  std::optional<PendingStart> start;
  bool global_requested = false;  // ~global_localization was called
  bool global_available = false;  // the tracker has a global mode (or may have: not built yet)
  std::deque<StampedOdometry> odometry;
  bool stop = false;
  RosNodeStats stats;
  RosStatus last_status = RosStatus::kRelocalising;
  std::string last_note = "waiting for images";
  long frame_index = 0;

  Impl(const RosNodeOptions& o, ros::NodeHandle n, ros::NodeHandle p)
      : options(o), nh(n), pnh(p), it(nh), private_it(pnh), updater(nh, pnh) {}

  void Setup();
  void OnImage(const sensor_msgs::ImageConstPtr& msg);
  void OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg);
  void OnOdometry(const nav_msgs::OdometryConstPtr& msg);
  void OnJoints(const sensor_msgs::JointStateConstPtr& msg);
  void OnInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  bool OnGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  bool EnsureTracker();
  void ApplyStart();
  void Process(const PendingImage& image, Clock::time_point taken);
  void Publish(const TrackedFrame& out, const std_msgs::Header& header,
               const std::optional<Eigen::Isometry3d>& odom_from_base);
  void PublishOverlay(const TrackedFrame& out, const std_msgs::Header& header);
};

void RosNode::Impl::Setup() {
  TrackerSettings base;
  tracker_options.model_path = options.model;
  tracker_options.settings =
      options.settings.empty() ? base : ReadTrackerSettings(options.settings, base);
  tracker_options.sequence.integrity = options.integrity.Options();
  tracker_options.sequence.global = options.global.Options();
  global_available = tracker_options.sequence.global.enabled;
  mount_source = std::make_unique<CameraMountSource>(options.MountOptions(), nh);
  if (!options.camera.empty()) {
    tracker_options.camera = LoadCamera(options.camera);
    if (tracker_options.camera.width <= 0) {
      throw InputError(options.camera + ": the camera file gives no image size");
    }
    EnsureTracker();
  } else {
    info_sub = nh.subscribe("camera_info", 1, &Impl::OnCameraInfo, this);
  }
  image_sub = it.subscribe("image", 2, &Impl::OnImage, this);
  odom_sub = nh.subscribe("odom", 100, &Impl::OnOdometry, this);
  if (options.MountOptions().Resolved() == HeadSource::kJointStates) {
    joints_sub = nh.subscribe("joint_states", 100, &Impl::OnJoints, this);
  }
  initial_sub = nh.subscribe("initialpose", 2, &Impl::OnInitialPose, this);
  pose_pub = pnh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10);
  degraded_pub = pnh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose_degraded", 10);
  status_pub = pnh.advertise<std_msgs::String>("status", 10, /*latch=*/true);
  overlay_pub = private_it.advertise("overlay", 1);
  global_srv = pnh.advertiseService("global_localization", &Impl::OnGlobalLocalization, this);
  updater.setHardwareID("linetrack");
  updater.add("localisation", this, &Impl::Diagnose);
}

void RosNode::Impl::OnImage(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex);
  ++stats.received;
  if (pending.Put(PendingImage{msg, Clock::now()})) ++stats.dropped;  // the older one went
  wake.notify_one();
}

void RosNode::Impl::OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex);
  if (camera_from_info) return;
  try {
    camera_from_info = CameraFromInfo(*msg);
  } catch (const InputError& e) {
    ROS_ERROR_THROTTLE(10.0, "linetrack: %s", e.what());
  }
}

void RosNode::Impl::OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex);
  StampedOdometry reading{msg->header.stamp.toSec(), ToIsometry(msg->pose.pose)};
  if (!odometry.empty() && reading.t < odometry.back().t) odometry.clear();  // time went back
  odometry.push_back(reading);
  while (!odometry.empty() && odometry.back().t - odometry.front().t > 10.0)
    odometry.pop_front();
  wake.notify_one();  // an image may be waiting for this reading
}

void RosNode::Impl::OnJoints(const sensor_msgs::JointStateConstPtr& msg) {
  mount_source->OnJoints(*msg);
}

void RosNode::Impl::OnInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  if (!msg->header.frame_id.empty() && msg->header.frame_id != options.map_frame) {
    ROS_WARN("linetrack: initialpose in frame '%s', not '%s': ignored",
             msg->header.frame_id.c_str(), options.map_frame.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex);
  start = PendingStart{PlanarOf(ToIsometry(msg->pose.pose)), ToMatrix6(msg->pose.covariance),
                       msg->header.stamp.toSec()};
  global_requested = false;  // the newest request wins
}

bool RosNode::Impl::OnGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex);
  if (!global_available) {
    ROS_ERROR(
        "linetrack: no global mode (disabled, or the model has no horizontal edges); give the "
        "pose on initialpose (RViz's 2D Pose Estimate)");
    return false;
  }
  global_requested = true;
  start.reset();  // the global mode replaces any initial pose not yet applied
  ROS_INFO("linetrack: global localisation asked: the prior is dropped");
  return true;
}

void RosNode::Impl::Diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex);
  using diagnostic_msgs::DiagnosticStatus;
  unsigned char level = DiagnosticStatus::WARN;
  if (last_status == RosStatus::kTracking) level = DiagnosticStatus::OK;
  if (last_status == RosStatus::kLost) level = DiagnosticStatus::ERROR;
  status.summary(level,
                 std::string(ToString(last_status)) + (last_note.empty() ? "" : ": " + last_note));
  status.add("images received", stats.received);
  status.add("images dropped", stats.dropped);
  status.add("images processed", stats.processed);
  status.add("poses published", stats.with_pose);
  status.add("degraded poses published", stats.degraded);
  status.add("images without a camera mount", stats.no_mount);
  status.add("head angles from", mount_source->LastSource());
  if (!stats.track_ms.empty()) {
    status.add("tracking step median (ms)", QuantileNearestRank(stats.track_ms, 0.5));
    status.add("latency beyond tracking median (ms)", QuantileNearestRank(stats.overhead_ms, 0.5));
  }
}

bool RosNode::Impl::EnsureTracker() {
  if (tracker) return true;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (options.camera.empty()) {
      if (!camera_from_info) return false;
      tracker_options.camera = *camera_from_info;
    }
  }
  tracker = std::make_unique<RosTracker>(tracker_options);
  occlusion = std::make_unique<OcclusionTester>(tracker->model());
  std::lock_guard<std::mutex> lock(mutex);
  global_available = tracker->has_global_mode();
  return true;
}

void RosNode::Impl::ApplyStart() {
  std::optional<PendingStart> s;
  std::optional<Eigen::Isometry3d> odom;
  {
    std::lock_guard<std::mutex> lock(mutex);
    s.swap(start);
    if (!s) return;
    const std::vector<StampedOdometry> readings(odometry.begin(), odometry.end());
    odom = OdometryAt(readings, s->t, options.odom_max_gap);
    if (!odom && !readings.empty()) odom = readings.back().odom_from_base;
  }
  const SearchBounds bounds =
      BoundsFromCovariance(s->covariance, RelocalizationOptions(), options.initial_bounds_scale);
  map_from_odom.reset();
  tracker->Restart(s->map_base, odom ? std::optional<Pose3Dof>(PlanarOf(*odom)) : std::nullopt,
                   bounds);
  ROS_INFO("linetrack: initial pose (%.2f, %.2f, %.1f deg), matcher bounds %.2f m, %.1f deg",
           s->map_base.x, s->map_base.y, RadToDeg(s->map_base.heading), bounds.delta_t,
           RadToDeg(bounds.delta_phi));
}

void RosNode::Impl::Process(const PendingImage& image, Clock::time_point taken) {
  const std_msgs::Header& header = image.msg->header;
  vpImage<unsigned char> grey;
  try {
    grey = ToGreyImage(image.msg);
  } catch (const InputError& e) {
    ROS_ERROR_THROTTLE(10.0, "linetrack: %s", e.what());
    return;
  }
  if (static_cast<int>(grey.getWidth()) != tracker_options.camera.width ||
      static_cast<int>(grey.getHeight()) != tracker_options.camera.height) {
    ROS_ERROR_THROTTLE(10.0, "linetrack: image %ux%u but the camera is %dx%d", grey.getWidth(),
                       grey.getHeight(), tracker_options.camera.width,
                       tracker_options.camera.height);
    return;
  }
  TrackerInput input;
  input.t = header.stamp.toSec();
  std::string why;
  const std::optional<CameraMount> mount = mount_source->At(header, &why);
  if (!mount) {
    ROS_ERROR_THROTTLE(10.0, "linetrack: no camera mount: %s", why.c_str());
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.no_mount;
    last_note = "no camera mount: " + why;
    return;
  }
  input.mount = *mount;
  std::optional<Eigen::Isometry3d> odom;
  {
    std::unique_lock<std::mutex> lock(mutex);
    wake.wait_for(lock, std::chrono::duration<double>(options.odom_wait),
                  [&] { return stop || odometry.empty() || odometry.back().t >= input.t; });
    const std::vector<StampedOdometry> readings(odometry.begin(), odometry.end());
    odom = OdometryAt(readings, input.t, options.odom_max_gap);
  }
  if (odom) input.odom_base = PlanarOf(*odom);
  ApplyStart();  // after the odometry's wait: the initial pose is anchored to its reading
  bool global = false;
  {
    std::lock_guard<std::mutex> lock(mutex);
    std::swap(global, global_requested);
  }
  if (global && tracker->RequestGlobal()) map_from_odom.reset();
  const TrackedFrame out = tracker->Process(grey, input);
  Publish(out, header, odom);
  const double busy_ms = std::chrono::duration<double, std::milli>(Clock::now() - taken).count();
  const double wait_ms = std::chrono::duration<double, std::milli>(taken - image.arrival).count();
  {
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.processed;
    if (out.map_from_base)
      ++(out.status == RosStatus::kTracking ? stats.with_pose : stats.degraded);
    stats.track_ms.push_back(out.track_ms);
    stats.overhead_ms.push_back(busy_ms - out.track_ms);
    stats.wait_ms.push_back(wait_ms);
    if (stats.track_ms.size() > kMaxTimings) {  // the most recent half is kept
      stats.track_ms.erase(stats.track_ms.begin(), stats.track_ms.begin() + kMaxTimings / 2);
      stats.overhead_ms.erase(stats.overhead_ms.begin(),
                              stats.overhead_ms.begin() + kMaxTimings / 2);
      stats.wait_ms.erase(stats.wait_ms.begin(), stats.wait_ms.begin() + kMaxTimings / 2);
    }
    last_status = out.status;
    last_note = out.note;
  }
  PublishOverlay(out, header);
  ++frame_index;
}

// Tracking poses go on ~pose and set map -> odom; the others (degraded, or a matcher's pose being
// confirmed) on ~pose_degraded only, so that a consumer fusing ~pose never takes one blindly.
// map -> odom, from the last tracking pose, is sent with every frame's stamp.
void RosNode::Impl::Publish(const TrackedFrame& out, const std_msgs::Header& header,
                            const std::optional<Eigen::Isometry3d>& odom_from_base) {
  if (out.map_from_base) {
    geometry_msgs::PoseWithCovarianceStamped pose;
    pose.header.stamp = header.stamp;
    pose.header.frame_id = options.map_frame;
    pose.pose.pose = ToPoseMsg(*out.map_from_base);
    if (out.covariance) pose.pose.covariance = ToCovarianceMsg(*out.covariance);
    const bool tracking = out.status == RosStatus::kTracking;
    (tracking ? pose_pub : degraded_pub).publish(pose);
    if (tracking && odom_from_base) {
      map_from_odom = MapFromOdom(*out.map_from_base, *odom_from_base);
    }
  }
  // As AMCL: the last correction is sent on every frame, so that map -> odom stays current.
  if (map_from_odom) {
    geometry_msgs::TransformStamped transform;
    transform.header.stamp = header.stamp + ros::Duration(options.transform_tolerance);
    transform.header.frame_id = options.map_frame;
    transform.child_frame_id = options.odom_frame;
    transform.transform = ToTransformMsg(*map_from_odom);
    tf.sendTransform(transform);
  }
  std_msgs::String status;
  status.data = ToString(out.status);
  status_pub.publish(status);
}

void RosNode::Impl::PublishOverlay(const TrackedFrame& out, const std_msgs::Header& header) {
  if (overlay_pub.getNumSubscribers() == 0) return;
  std::vector<Segment2> edges;
  if (out.cam_from_map) {
    for (const ProjectedEdge& e : ProjectVisibleEdges(
             tracker->model(), *occlusion, *out.cam_from_map, tracker->undistorted_camera())) {
      edges.push_back(e.image);
    }
  }
  const cv::Mat bgr =
      DrawOverlay(tracker->undistorted(), edges, out.report, frame_index, header.stamp.toSec());
  overlay_pub.publish(
      cv_bridge::CvImage(header, sensor_msgs::image_encodings::BGR8, bgr).toImageMsg());
}

RosNode::RosNode(const RosNodeOptions& options, ros::NodeHandle nh, ros::NodeHandle private_nh)
    : impl_(std::make_unique<Impl>(options, nh, private_nh)) {
  options.Check();
  impl_->Setup();
}

RosNode::~RosNode() = default;

void RosNode::Run() {
  Impl& m = *impl_;
  while (ros::ok()) {
    std::optional<Impl::PendingImage> image;
    {
      std::unique_lock<std::mutex> lock(m.mutex);
      m.wake.wait_for(lock, std::chrono::milliseconds(100),
                      [&] { return m.pending.waiting() || m.stop; });
      if (m.stop) break;
      image = m.pending.Take();
    }
    const Clock::time_point taken = Clock::now();
    if (image && m.EnsureTracker()) m.Process(*image, taken);
    m.updater.update();
  }
}

void RosNode::Stop() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->stop = true;
  impl_->wake.notify_one();
}

RosNodeStats RosNode::Stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace linetrack::app

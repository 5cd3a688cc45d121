#include "app/ros/bag_recording.h"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <map>

#include "app/ros/ros_geometry.h"
#include "app/ros/ros_messages.h"
#include "models/errors.h"
#include "tracking/tracker/robot_readings.h"

namespace linetrack::app {
namespace {

double StampOf(const ros::Time& header, const ros::Time& recorded) {
  return header.isZero() ? recorded.toSec() : header.toSec();
}

// The images of one topic, in the bag's order.
class BagFrames : public FrameSource {
 public:
  BagFrames(const rosbag::Bag& bag, const std::string& path, const std::string& topic)
      : path_(path),
        topic_(topic),
        view_(bag, rosbag::TopicQuery(topic)),
        it_(view_.begin()),
        count_(static_cast<long>(view_.size())) {}

  FrameStatus Grab(Frame* frame) override {
    if (it_ == view_.end()) return FrameStatus::kEndOfStream;
    sensor_msgs::ImageConstPtr msg;
    ros::Time recorded;
    try {
      recorded = it_->getTime();
      msg = it_->instantiate<sensor_msgs::Image>();
      ++it_;
    } catch (const std::exception& e) {
      throw InputError(path_ + ": " + topic_ + ": " + e.what());
    }
    if (!msg) throw InputError(path_ + ": " + topic_ + ": not a sensor_msgs/Image");
    frame->image = ToGreyImage(msg);
    frame->timestamp_s = StampOf(msg->header.stamp, recorded);
    frame->frame_id = static_cast<std::uint64_t>(stats_.delivered);
    frame->index = stats_.delivered++;
    return FrameStatus::kOk;
  }
  std::string Describe() const override { return "rosbag " + path_ + " " + topic_; }
  SourceStats Stats() const override { return stats_; }
  long Count() const { return count_; }

 private:
  std::string path_, topic_;
  rosbag::View view_;
  rosbag::View::iterator it_;
  long count_ = 0;
  SourceStats stats_;
};

// Every message of `topic` as T, in the bag's order, with the stamp it was recorded at.
template <typename T>
std::vector<std::pair<ros::Time, boost::shared_ptr<T>>> ReadAll(const rosbag::Bag& bag,
                                                                const std::string& topic) {
  std::vector<std::pair<ros::Time, boost::shared_ptr<T>>> all;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    boost::shared_ptr<T> msg = m.instantiate<T>();
    if (msg) all.emplace_back(m.getTime(), msg);
  }
  return all;
}

class RosBagRecording : public Recording {
 public:
  RosBagRecording(const std::string& path, const RecordingOptions& options);

  FrameSource& frames() override { return *frames_; }
  long FrameCount() const override { return frames_->Count(); }
  double FrameRate() const override { return frame_rate_; }
  const std::vector<PriorRecord>& priors() const override { return priors_; }
  std::optional<CameraIntrinsics> camera() const override { return camera_; }
  void Add(double t, const FrameReport& report) override;
  void Finish() override;

 private:
  void CheckTopics();
  void ReadReadings();
  CameraMount MountAt(double t) const;

  std::string path_;
  RecordingOptions options_;
  rosbag::Bag bag_;
  std::unique_ptr<BagFrames> frames_;
  double frame_rate_ = 30.0;
  std::vector<StampedOdometry> odometry_;
  std::vector<StampedHeadAngles> joints_;
  std::vector<PriorRecord> priors_;
  std::optional<CameraIntrinsics> camera_;
  std::unique_ptr<rosbag::Bag> out_;
  std::string out_part_;
};

RosBagRecording::RosBagRecording(const std::string& path, const RecordingOptions& options)
    : path_(path), options_(options) {
  try {
    bag_.open(path, rosbag::bagmode::Read);
    CheckTopics();
    ReadReadings();
    frames_ = std::make_unique<BagFrames>(bag_, path_, options_.image_topic);
  } catch (const rosbag::BagUnindexedException&) {
    throw InputError(path + ": the bag is not indexed (rosbag reindex)");
  } catch (const rosbag::BagException& e) {
    throw InputError(path + ": not a readable bag (" + e.what() + ")");
  }
  if (frames_->Count() == 0) throw InputError(path + ": no image on " + options_.image_topic);
  if (!options_.out_bag.empty()) {
    out_part_ = options_.out_bag + ".part";
    out_ = std::make_unique<rosbag::Bag>();
    try {
      out_->open(out_part_, rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      throw InputError(options_.out_bag + ": cannot be written (" + e.what() + ")");
    }
  }
}

void RosBagRecording::CheckTopics() {
  std::map<std::string, std::string> types;
  rosbag::View all(bag_);
  for (const rosbag::ConnectionInfo* c : all.getConnections())
    types[c->topic] = c->datatype;
  const std::pair<std::string, const char*> wanted[] = {
      {options_.image_topic, "sensor_msgs/Image"},
      {options_.odom_topic, "nav_msgs/Odometry"},
      {options_.camera_info_topic, "sensor_msgs/CameraInfo"},
      {options_.joint_states_topic, "sensor_msgs/JointState"}};
  for (const auto& [topic, type] : wanted) {
    if (topic.empty()) continue;
    const auto it = types.find(topic);
    if (it == types.end()) throw InputError(path_ + ": no topic " + topic + " in the bag");
    if (it->second != type) {
      throw InputError(path_ + ": topic " + topic + " holds " + it->second + ", not " + type);
    }
  }
}

void RosBagRecording::ReadReadings() {
  if (!options_.camera_info_topic.empty()) {
    const auto infos = ReadAll<sensor_msgs::CameraInfo>(bag_, options_.camera_info_topic);
    if (infos.empty()) throw InputError(path_ + ": no message on " + options_.camera_info_topic);
    camera_ = CameraFromInfo(*infos.front().second);
  }
  for (const auto& [recorded, msg] :
       ReadAll<sensor_msgs::JointState>(bag_, options_.joint_states_topic)) {
    StampedHeadAngles reading{StampOf(msg->header.stamp, recorded), 0.0, options_.tilt};
    for (size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i) {
      if (msg->name[i] == options_.pan_joint) reading.pan = msg->position[i];
      if (msg->name[i] == options_.tilt_joint) reading.tilt = msg->position[i];
    }
    joints_.push_back(reading);
  }
  std::sort(joints_.begin(), joints_.end(),
            [](const StampedHeadAngles& a, const StampedHeadAngles& b) { return a.t < b.t; });
  // Every image once: their stamps (the frame rate, the first frame where --prior holds), and a
  // truncated or corrupt chunk found before any output is written.
  std::vector<double> stamps;
  for (const auto& [recorded, msg] : ReadAll<sensor_msgs::Image>(bag_, options_.image_topic))
    stamps.push_back(StampOf(msg->header.stamp, recorded));
  const double step = MedianTimeStep(stamps);
  if (step > 0.0) frame_rate_ = 1.0 / step;
  if (options_.odom_topic.empty()) return;
  for (const auto& [recorded, msg] : ReadAll<nav_msgs::Odometry>(bag_, options_.odom_topic))
    odometry_.push_back({StampOf(msg->header.stamp, recorded), ToIsometry(msg->pose.pose)});
  std::stable_sort(odometry_.begin(), odometry_.end(),
                   [](const StampedOdometry& a, const StampedOdometry& b) { return a.t < b.t; });
  odometry_.erase(
      std::unique(odometry_.begin(), odometry_.end(),
                  [](const StampedOdometry& a, const StampedOdometry& b) { return a.t == b.t; }),
      odometry_.end());
  if (odometry_.empty()) throw InputError(path_ + ": no message on " + options_.odom_topic);
  Eigen::Isometry3d map_from_odom = Eigen::Isometry3d::Identity();
  if (options_.start && !stamps.empty()) {
    const Eigen::Isometry3d first =
        OdometryAt(odometry_, stamps.front(), 1e9).value_or(Eigen::Isometry3d::Identity());
    map_from_odom = PlanarIsometry(*options_.start) * PlanarIsometry(PlanarOf(first)).inverse();
  }
  for (const StampedOdometry& o : odometry_) {
    const Pose3Dof base = PlanarOf(map_from_odom * PlanarIsometry(PlanarOf(o.odom_from_base)));
    priors_.push_back({o.t, CameraPrior(base, MountAt(o.t))});
  }
}

CameraMount RosBagRecording::MountAt(double t) const {
  // The nearest reading however far: a bag's joint states start and end with its images.
  const std::optional<StampedHeadAngles> angles =
      HeadAnglesAt(joints_, t, std::numeric_limits<double>::infinity());
  const double pan = angles ? angles->pan : 0.0;
  const double tilt = angles ? angles->tilt : options_.tilt;
  if (options_.head) {
    return MountOnHead(options_.head->geometry, options_.head->crossing_height, pan, tilt);
  }
  return CameraMount{options_.height, pan, tilt};
}

void RosBagRecording::Add(double t, const FrameReport& report) {
  if (!out_ || !report.cam_from_world) return;
  const CameraMount mount = MountAt(t);
  const Eigen::Isometry3d map_from_base = MapFromBase(*report.cam_from_world, mount);
  const ros::Time stamp(t);
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = stamp;
  pose.header.frame_id = "map";
  pose.pose.pose = ToPoseMsg(map_from_base);
  const std::optional<Matrix6d> covariance =
      RosCovarianceOf(report.uncertainty, *report.cam_from_world, mount);
  if (covariance) pose.pose.covariance = ToCovarianceMsg(*covariance);
  // As the node: tracking poses on the pose topic with map -> odom, the others apart.
  const bool tracking = covariance && report.uncertainty.status == IntegrityStatus::kTracking;
  out_->write(tracking ? "/linetrack/pose" : "/linetrack/pose_degraded", stamp, pose);
  const std::optional<Eigen::Isometry3d> odom = OdometryAt(odometry_, t, 0.5);
  if (!tracking || !odom) return;
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = stamp;
  transform.header.frame_id = "map";
  transform.child_frame_id = "odom";
  transform.transform = ToTransformMsg(MapFromOdom(map_from_base, *odom));
  tf.transforms.push_back(transform);
  out_->write("/tf", stamp, tf);
}

void RosBagRecording::Finish() {
  if (!out_) return;
  out_->close();
  out_.reset();
  std::filesystem::rename(out_part_, options_.out_bag);
}

}  // namespace

std::unique_ptr<Recording> OpenRosBag(const std::string& path, const RecordingOptions& options) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path + ": no such bag file");
  return std::make_unique<RosBagRecording>(path, options);
}

}  // namespace linetrack::app

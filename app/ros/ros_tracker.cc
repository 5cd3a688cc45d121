#include "app/ros/ros_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "models/errors.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

RosStatus StatusOf(IntegrityStatus integrity, bool reacquiring) {
  if (integrity == IntegrityStatus::kTracking) return RosStatus::kTracking;
  if (integrity == IntegrityStatus::kLost) return RosStatus::kLost;
  return reacquiring ? RosStatus::kRelocalising : RosStatus::kDegraded;
}

const char* ToString(RosStatus status) {
  switch (status) {
    case RosStatus::kTracking:
      return "tracking";
    case RosStatus::kDegraded:
      return "degraded";
    case RosStatus::kLost:
      return "lost";
    case RosStatus::kRelocalising:
      return "relocalising";
  }
  return "unknown";
}

bool RosTrackerOptions::Check(std::string* why) const {
  if (model_path.empty()) {
    *why = "no model";
    return false;
  }
  if (camera.width <= 0 || camera.height <= 0) {
    *why = "the camera's image size is unknown";
    return false;
  }
  return relocalization.Check(why) && sequence.Check(why);
}

RosTracker::RosTracker(const RosTrackerOptions& options)
    : options_(options),
      cache_(LocalizerOptions()),
      loaded_(cache_.Model(options.model_path)),
      undistorted_camera_(options.camera.Undistorted()) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("ros: " + why);
  LocalizerOptions matcher;
  matcher.noise = DetectedLineNoise();  // lines from LineExtractor
  localizer_ = std::make_unique<Localizer>(*loaded_.model, loaded_.regions.get(),
                                           loaded_.area.get(), options_.camera, matcher);
  tracker_ = std::make_unique<EdgeTracker>(options_.model_path, options_.camera, options_.settings);
  relocalizer_ = std::make_unique<Relocalizer>(
      *localizer_, MakeLineExtractorFunction(options_.lines), options_.relocalization);
  if (options_.sequence.global.enabled && !loaded_.directions.angles.empty()) {
    global_localizer_ = std::make_unique<GlobalLocalizer>(*localizer_, loaded_.directions,
                                                          GlobalOptionsFor(matcher));
    global_ = std::make_unique<GlobalRecovery>(*global_localizer_,
                                               MakeLineExtractorFunction(options_.lines),
                                               options_.relocalization.min_lines);
  }
  sequence_ = std::make_unique<SequenceTracker>(tracker_.get(), options_.camera, relocalizer_.get(),
                                                options_.sequence);
  sequence_->SetGlobalRecovery(global_.get());
}

RosTracker::~RosTracker() = default;

bool RosTracker::RequestGlobal() {
  if (!global_) return false;
  sequence_->RequestGlobal();
  unanchored_start_.reset();
  had_pose_ = false;
  return true;
}

void RosTracker::Restart(const Pose3Dof& map_base, const std::optional<Pose3Dof>& odom_base,
                         const SearchBounds& bounds) {
  RelocalizationOptions relocalization = options_.relocalization;
  relocalization.initial = bounds;
  relocalizer_ = std::make_unique<Relocalizer>(
      *localizer_, MakeLineExtractorFunction(options_.lines), relocalization);
  sequence_ = std::make_unique<SequenceTracker>(tracker_.get(), options_.camera, relocalizer_.get(),
                                                options_.sequence);
  sequence_->SetGlobalRecovery(global_.get());
  map_from_odom_ = odom_base ? PlanarIsometry(map_base) * PlanarIsometry(*odom_base).inverse()
                             : Eigen::Isometry3d::Identity();
  unanchored_start_.reset();
  if (!odom_base) unanchored_start_ = map_base;
  // Without odometry the prior stays where the initial pose put the base.
  if (!odom_base) sequence_->SetInitialPrior(map_base);
  had_pose_ = false;
}

TrackedFrame RosTracker::Process(const vpImage<unsigned char>& image, const TrackerInput& input) {
  const Clock::time_point start = Clock::now();
  RobotReading reading;
  reading.height = input.mount.height;
  reading.tilt = input.mount.tilt;
  reading.roll = input.mount.roll;
  if (input.odom_base && unanchored_start_) {  // the robot still where the initial pose put it
    map_from_odom_ =
        PlanarIsometry(*unanchored_start_) * PlanarIsometry(*input.odom_base).inverse();
    unanchored_start_.reset();
  }
  if (input.odom_base) {
    const Pose3Dof map_base = PlanarOf(map_from_odom_ * PlanarIsometry(*input.odom_base));
    reading.odometry = CameraPrior(map_base, input.mount).Planar();
  }
  const FrameReport report = sequence_->Process(image, input.t, reading);
  TrackedFrame out;
  out.track_status = report.status;
  out.source = report.source;
  out.note = report.note;
  out.report = report;
  if (report.cam_from_world) {
    had_pose_ = true;
    out.cam_from_map = report.cam_from_world;
    out.map_from_base = MapFromBase(*report.cam_from_world, input.mount);
    out.covariance = RosCovarianceOf(report.uncertainty, *report.cam_from_world, input.mount);
    out.status = out.covariance ? StatusOf(report.uncertainty.status, sequence_->reacquiring())
                                : RosStatus::kDegraded;
    if (out.status != RosStatus::kTracking) out.note = report.uncertainty.reason;
  } else {
    out.status = had_pose_ && report.status == TrackStatus::kLost ? RosStatus::kLost
                                                                  : RosStatus::kRelocalising;
  }
  out.track_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  return out;
}

}  // namespace linetrack::app

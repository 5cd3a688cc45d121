#include "tracking/live/tracker_estimator.h"

namespace linetrack {

PoseStatus PoseStatusOf(TrackStatus status) {
  switch (status) {
    case TrackStatus::kInitialising:
      return PoseStatus::kInitialising;
    case TrackStatus::kTracking:
      return PoseStatus::kTracking;
    case TrackStatus::kLost:
      return PoseStatus::kLost;
    case TrackStatus::kRelocalised:
      return PoseStatus::kRelocalised;
    case TrackStatus::kCoasting:
      return PoseStatus::kCoasting;
  }
  return PoseStatus::kLost;
}

RobotReading RobotReadingOf(const RobotPose& camera_prior) {
  RobotReading reading;
  reading.odometry = camera_prior.Planar();
  reading.height = camera_prior.height;
  reading.tilt = camera_prior.tilt;
  reading.roll = camera_prior.roll;
  return reading;
}

TrackerPoseEstimator::TrackerPoseEstimator(const WireframeModel& model, const NavigableArea& area,
                                           const CameraIntrinsics& camera,
                                           const TrackerEstimatorOptions& options)
    : regions_(ViewInvariantRegions::Build(model, area)),
      settings_source_(options.settings.source) {
  engine_ = std::make_unique<TrackingEngine>(
      TrackingEngineModel{model.path(), &model, &regions_, &area}, camera, options);
}

TrackerPoseEstimator::~TrackerPoseEstimator() = default;

PoseEstimate TrackerPoseEstimator::Estimate(const Frame& frame, const HeadState& /*head*/,
                                            const RobotPose& camera_prior) {
  last_report_ = engine_->Process(frame.image, frame.timestamp_s, RobotReadingOf(camera_prior));
  PoseEstimate estimate;
  estimate.status = PoseStatusOf(last_report_.status);
  estimate.cam_from_world = last_report_.cam_from_world;
  estimate.source = last_report_.source;
  estimate.note = last_report_.note;
  estimate.uncertainty = last_report_.uncertainty;
  if (last_report_.health_measured) {
    estimate.projection_error_deg = last_report_.health.projection_error_deg;
  }
  return estimate;
}

std::string TrackerPoseEstimator::Describe() const {
  return "moving-edge tracker started and recovered by the matcher (settings: " + settings_source_ +
         ")";
}

}  // namespace linetrack

// The moving-edge tracker of tracking/tracker/ behind the live loop's seam (pose_estimator.h):
// each frame goes to SequenceTracker::Process with the robot's reading for the frame, taken from
// the loop's camera prior: position and heading (base heading + pan) as odometry, height and tilt
// from the head. So the matcher that starts and recovers the tracker searches around where the
// head points now (the paper's "tilt known but variable" case), and the tracker's checks of
// height, tilt and motion follow the head.
#pragma once

#include <memory>
#include <string>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/view_invariant_regions.h"
#include "models/wireframe.h"
#include "tracking/live/pose_estimator.h"
#include "tracking/tracker/tracking_engine.h"

namespace linetrack {

// The tracker's status in the live loop's vocabulary (the same four states).
PoseStatus PoseStatusOf(TrackStatus status);

// The robot's reading for the tracker from the loop's camera prior: odometry (x, y, heading),
// height, tilt and roll.
RobotReading RobotReadingOf(const RobotPose& camera_prior);

// What the tracker is made of: the tracking engine's options.
using TrackerEstimatorOptions = TrackingEngineOptions;

class TrackerPoseEstimator : public CameraPoseEstimator {
 public:
  // Builds the view-invariant regions of `model` in `area`, the matcher, the line extractor and
  // the moving-edge tracker (ViSP loads model.path()) for frames of `camera` (with its size and
  // distortion: frames are undistorted inside). `model` and `area` must outlive the estimator.
  // Throws InputError on invalid options or a model ViSP cannot load.
  TrackerPoseEstimator(const WireframeModel& model, const NavigableArea& area,
                       const CameraIntrinsics& camera, const TrackerEstimatorOptions& options);
  ~TrackerPoseEstimator() override;

  PoseEstimate Estimate(const Frame& frame, const HeadState& head,
                        const RobotPose& camera_prior) override;
  std::string Describe() const override;

  // The last frame's report (timings, health, lines).
  const FrameReport& last_report() const { return last_report_; }
  int losses() const { return engine_->sequence().losses(); }
  int recoveries() const { return engine_->sequence().recoveries(); }

 private:
  ViewInvariantRegions regions_;
  std::unique_ptr<TrackingEngine> engine_;
  std::string settings_source_;
  FrameReport last_report_;
};

}  // namespace linetrack

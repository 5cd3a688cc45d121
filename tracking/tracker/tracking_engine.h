// The tracking engine that replay, live and the ROS node drive: the moving-edge tracker
// (edge_tracker.h) with its checks and integrity monitor (sequence_tracker.h), started and
// recovered by the interpretation-tree matcher (relocalizer.h) when the model's view-invariant
// regions and navigable area are given. One frame in, one FrameReport out.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "matching/global/global_localizer.h"
#include "matching/heading/model_directions.h"
#include "matching/lines/line_extractor.h"
#include "matching/localizer.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/view_invariant_regions.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/global_recovery.h"
#include "tracking/tracker/relocalizer.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {

// What the engine is made of.
struct TrackingEngineOptions {
  LocalizerOptions matcher;     // the matcher for (re-)localisation (set for detected lines)
  LineExtractionOptions lines;  // line extraction of the undistorted frames
  RelocalizationOptions relocalization;
  TrackerSettings settings;         // moving edges, visibility, passes
  SequenceTrackerOptions sequence;  // health, motion, robot checks and the integrity monitor
};

// The model and, for the matcher, its regions and navigable area (both null: no matcher, the
// tracker starts only from SetStartPose). All must outlive the engine.
struct TrackingEngineModel {
  std::string path;  // the .cao file ViSP's tracker loads
  const WireframeModel* model = nullptr;
  const ViewInvariantRegions* regions = nullptr;
  const NavigableArea* area = nullptr;
};

class TrackingEngine {
 public:
  // Builds the matcher (when regions and area are given), its global mode (with
  // options.sequence.global.enabled and horizontal model edges), the line extractor and the tracker
  // for frames of `camera` (distorted as they come: undistorted inside). Throws InputError on
  // invalid options or a model ViSP cannot load.
  TrackingEngine(const TrackingEngineModel& model, const CameraIntrinsics& camera,
                 const TrackingEngineOptions& options);
  ~TrackingEngine();
  TrackingEngine(const TrackingEngine&) = delete;
  TrackingEngine& operator=(const TrackingEngine&) = delete;

  // Tracks one frame taken at `t` seconds, with the robot's reading (odometry, height, tilt)
  // when there is one.
  FrameReport Process(const vpImage<unsigned char>& image, double t,
                      const std::optional<RobotReading>& robot) {
    return sequence_->Process(image, t, robot);
  }

  SequenceTracker& sequence() { return *sequence_; }
  const SequenceTracker& sequence() const { return *sequence_; }
  bool has_matcher() const { return relocalizer_ != nullptr; }
  bool has_global_mode() const { return global_ != nullptr; }

 private:
  std::unique_ptr<Localizer> localizer_;
  std::unique_ptr<Relocalizer> relocalizer_;
  ModelDirections directions_;
  std::unique_ptr<GlobalLocalizer> global_localizer_;
  std::unique_ptr<GlobalRecovery> global_;
  std::unique_ptr<EdgeTracker> tracker_;
  std::unique_ptr<SequenceTracker> sequence_;
};

}  // namespace linetrack

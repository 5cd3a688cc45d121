#include "tracking/tracker/tracking_engine.h"

namespace linetrack {

TrackingEngine::TrackingEngine(const TrackingEngineModel& model, const CameraIntrinsics& camera,
                               const TrackingEngineOptions& options) {
  if (model.model != nullptr && model.regions != nullptr && model.area != nullptr) {
    localizer_ = std::make_unique<Localizer>(*model.model, model.regions, model.area, camera,
                                             options.matcher);
    // The tracker hands undistorted frames over: segments stay in their pixels (no camera).
    relocalizer_ = std::make_unique<Relocalizer>(
        *localizer_, MakeLineExtractorFunction(options.lines), options.relocalization);
    directions_ = DominantDirections(*model.model);
    if (options.sequence.global.enabled && !directions_.angles.empty()) {
      global_localizer_ = std::make_unique<GlobalLocalizer>(*localizer_, directions_,
                                                            GlobalOptionsFor(options.matcher));
      global_ = std::make_unique<GlobalRecovery>(*global_localizer_,
                                                 MakeLineExtractorFunction(options.lines),
                                                 options.relocalization.min_lines);
    }
  }
  tracker_ = std::make_unique<EdgeTracker>(model.path, camera, options.settings);
  sequence_ = std::make_unique<SequenceTracker>(tracker_.get(), camera, relocalizer_.get(),
                                                options.sequence);
  sequence_->SetGlobalRecovery(global_.get());
}

TrackingEngine::~TrackingEngine() = default;

}  // namespace linetrack

#include "models/render/drive_renderer.h"

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {

DriveRenderer::DriveRenderer(const WireframeModel& model, SceneRenderer* renderer,
                             std::vector<SequenceFrame> frames, DriveEffects effects,
                             const DriveEffectsOptions& options,
                             const ObservabilityOptions& observability)
    : model_(model),
      renderer_(renderer),
      frames_(std::move(frames)),
      effects_(std::move(effects)),
      options_(options),
      observability_(observability),
      occlusion_(model) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("drive effects: " + why);
  if (!observability_.Check(&why)) throw InputError("observability: " + why);
}

DriveRenderer::Rendered DriveRenderer::RenderFrame(size_t k) {
  const SequenceFrame& frame = frames_.at(k);
  Rendered out;
  FrameTruth& truth = out.truth;
  truth.frame = static_cast<long>(k);
  truth.t = frame.t;
  truth.pan_deg = RadToDeg(frame.pan);
  truth.covered = effects_.CoveredAt(frame.t);
  truth.gain = effects_.GainAt(frame.t);

  renderer_->SetMovingSurfaces(effects_.PeopleAt(frame.t));
  FrameExposure exposure;
  exposure.frame_index = static_cast<int>(k);
  exposure.gain = truth.gain;
  exposure.covered = truth.covered;
  exposure.shutter =
      ShutterPoses(frames_, k, renderer_->camera().Undistorted(), options_, &truth.blur_px);
  truth.shutter_samples = static_cast<int>(exposure.shutter.size());
  out.image = renderer_->Render(exposure);
  if (truth.covered) return out;

  const SurfaceMap seen = renderer_->RenderSurfaces(frame.cam_from_world);
  const FrameObservation observation =
      ObserveFrame(model_, occlusion_, renderer_->camera().Undistorted(), frame.cam_from_world,
                   seen, renderer_->scene(), observability_);
  truth.observable = observation.observable;
  truth.observable_edges = observation.edges;
  truth.people_share = observation.people_share;
  truth.clutter_share = observation.clutter_share;
  truth.centre_depth_m = observation.centre_depth_m;
  return out;
}

}  // namespace linetrack

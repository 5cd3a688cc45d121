// Renders the frames of a sequence with its effects (people, covered lens, gain, motion blur)
// and the truth of each frame beyond its pose (observability, the effects it carries).
#pragma once

#include <visp3/core/vpImage.h>
#include <vector>

#include "models/occlusion.h"
#include "models/render/drive_effects.h"
#include "models/render/frame_truth.h"
#include "models/render/observability.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/wireframe.h"

namespace linetrack {

class DriveRenderer {
 public:
  // `renderer` draws `model`'s scene (neither owned; both outlive this object). Throws
  // InputError when the options are invalid.
  DriveRenderer(const WireframeModel& model, SceneRenderer* renderer,
                std::vector<SequenceFrame> frames, DriveEffects effects,
                const DriveEffectsOptions& options, const ObservabilityOptions& observability = {});

  struct Rendered {
    vpImage<unsigned char> image;
    FrameTruth truth;
  };

  // Frame k: the people at its time, its exposure (shutter poses, gain, covered lens) and its
  // truth (observability from the true pose: nothing is observable through a covered lens).
  Rendered RenderFrame(size_t k);

  size_t size() const { return frames_.size(); }
  const std::vector<SequenceFrame>& frames() const { return frames_; }
  const DriveEffects& effects() const { return effects_; }

 private:
  const WireframeModel& model_;
  SceneRenderer* renderer_;
  std::vector<SequenceFrame> frames_;
  DriveEffects effects_;
  DriveEffectsOptions options_;
  ObservabilityOptions observability_;
  OcclusionTester occlusion_;
};

}  // namespace linetrack

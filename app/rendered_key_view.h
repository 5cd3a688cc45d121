// Key views from rendered images (`views build --render`, `bench views`): the model rendered at
// the view's pose, its lines detected, each given the id of the model edge it lies along at the
// true pose (none for lines of unmodelled objects), and the junctions of the model's vertices
// whose two lines were both detected. Rendering and judging against the truth are evaluation
// code: they live in app/, not in the matching library.
#pragma once

#include <memory>

#include "matching/lines/line_extractor.h"
#include "matching/views/key_view.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"

namespace linetrack::app {

struct KeyViewRenderOptions {
  int clutter = 0;  // unmodelled objects in the rendered scene
  uint64_t seed = 1;
  LineExtractionOptions lines;
};

class KeyViewRenderer {
 public:
  // `camera` may have distortion (the images are distorted, the segments undistorted). Throws
  // InputError when the camera has no image size or the options are invalid.
  KeyViewRenderer(const WireframeModel& model, const NavigableArea& area,
                  const CameraIntrinsics& camera, const KeyViewRenderOptions& options);

  // The key view at `pose` whose visible edge pieces (undistorted camera) are `pieces`;
  // `frame` picks the image's noise draw.
  KeyView Render(const std::vector<ProjectedEdge>& pieces, const RobotPose& pose, int frame);

  // The detected segments of the image at `pose` (undistorted pixels).
  std::vector<Segment2> Lines(const RobotPose& pose, int frame);

 private:
  const WireframeModel& model_;
  SceneRenderer renderer_;
  LineExtractor extractor_;
};

}  // namespace linetrack::app

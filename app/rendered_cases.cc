#include "app/rendered_cases.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "matching/evaluation/line_evaluation.h"
#include "models/robot_pose.h"

namespace linetrack::app {
std::vector<RenderedCase> RenderCases(const WireframeModel& model, const NavigableArea& area,
                                      const OcclusionTester& occlusion,
                                      const RenderedCaseOptions& options) {
  SyntheticSceneOptions scene_options;
  scene_options.seed = options.seed;
  scene_options.count = options.count;
  scene_options.camera = options.camera;
  scene_options.calibration_sigma = options.calibration_sigma;
  scene_options.delta_t = options.delta_t;
  scene_options.delta_phi = options.delta_phi;
  scene_options.max_visible_edges = options.max_visible_edges;
  RenderOptions render_options;
  render_options.scene.seed = options.seed;
  render_options.scene.clutter = options.clutter;
  RenderOptions clean_options = render_options;
  clean_options.noise_sigma = 0.0;
  std::vector<RenderedCase> cases;
  for (int i = 0; i < options.count; ++i) {
    RenderedCase c;
    c.scene = GenerateScene(model, occlusion, area, scene_options, i);
    c.image_camera = options.camera;
    c.image_camera.px *= 1.0 + c.scene.calibration_error;
    c.image_camera.py *= 1.0 + c.scene.calibration_error;
    c.cam_from_world = CamFromWorld(c.scene.truth);
    // One renderer per image camera: the focal error differs per case.
    SceneRenderer renderer(model, c.image_camera, render_options, &area);
    SceneRenderer clean(model, c.image_camera, clean_options, &area);
    c.image = renderer.Render(c.cam_from_world, i);
    const CameraIntrinsics undistorted = c.image_camera.Undistorted();
    c.truth = ProjectVisibleEdges(model, occlusion, c.cam_from_world, undistorted);
    c.observable = ObservablePieces(c.truth, clean.Render(c.cam_from_world, i),
                                    clean.RenderSurfaces(c.cam_from_world), clean.scene(),
                                    c.image_camera, c.cam_from_world, options.min_contrast);
    cases.push_back(std::move(c));
  }
  return cases;
}

}  // namespace linetrack::app

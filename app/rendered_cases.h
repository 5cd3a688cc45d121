// Rendered localisation cases for the image benchmarks: poses and priors drawn as `linetrack
// synth` draws them (models/synth/synthetic_scenes.h), each view rendered (models/render/) with its
// ground truth: the visible model edges projected with the true pose, and the parts of them an
// image can show (not hidden by unmodelled clutter, with an intensity step).
#pragma once

#include <visp3/core/vpImage.h>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "matching/evaluation/line_evaluation.h"
#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/render/scene_renderer.h"
#include "models/synth/synthetic_scenes.h"
#include "models/wireframe.h"

namespace linetrack::app {

// How the cases are drawn and rendered.
struct RenderedCaseOptions {
  int count = 50;
  uint64_t seed = 1;
  CameraIntrinsics camera = PaperSyntheticCamera();  // may have distortion
  int clutter = 10;                                  // unmodelled objects in the rendered scene
  double calibration_sigma = 0.0;     // relative focal error of the image camera (synth's eta_m)
  double delta_t = 0.75;              // prior bounds (default QI3), metres
  double delta_phi = DegToRad(20.0);  // radians
  int max_visible_edges = 12;         // synth's acceptance (5 to 12 model edges seen); wider lenses
                                      // see more
  // An edge sample is observable when the noise-free image steps by at least this much across
  // it (grey levels, between +-2 px; the sensor noise is 2) and no clutter hides it.
  double min_contrast = 8.0;
};

// One rendered view with its truth.
struct RenderedCase {
  SyntheticScene scene;           // pose drawn in the navigable area, prior, height, tilt
  CameraIntrinsics image_camera;  // the camera that made the image (focal error applied)
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  vpImage<unsigned char> image;
  std::vector<ProjectedEdge> truth;         // visible model edges (undistorted pixels)
  std::vector<ObservablePiece> observable;  // their parts not hidden by clutter, with contrast
};

// Cases 0 .. count - 1 (scene i of the synth series with these options, rendered with noise
// frame i). Throws InputError when the options are invalid.
std::vector<RenderedCase> RenderCases(const WireframeModel& model, const NavigableArea& area,
                                      const OcclusionTester& occlusion,
                                      const RenderedCaseOptions& options);

}  // namespace linetrack::app

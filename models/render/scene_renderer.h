// Renders a wireframe model's scene (render_scene.h) into a grey image: own z-buffer rasteriser
// with supersampling, per-face albedo, procedural texture stuck to the surfaces, soft lighting
// from ceiling lamps, optional radial distortion (ViSP model), blur and Gaussian sensor noise.
// Deterministic for a seed.
#pragma once

#include <visp3/core/vpImage.h>
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/render/render_scene.h"
#include "models/wireframe.h"

namespace linetrack {

struct RenderOptions {
  RenderSceneOptions scene;        // seed, frame bands, clutter
  int supersample = 2;             // samples per pixel side (anti-aliasing), 1..4
  double noise_sigma = 2.0;        // standard deviation of the sensor noise (grey levels)
  double blur_sigma = 0.7;         // standard deviation of the optical blur (pixels); 0: none
  bool apply_distortion = true;    // distort with the camera's kud/kdu model when it has one
  double texture_contrast = 0.05;  // relative amplitude of the surface texture
  double ambient = 0.55;           // share of the light that does not come from the lamps
  double exposure = 1.0;           // grey level = 255 exposure albedo (1 + texture) light
  double near_clip = 0.02;         // metres in front of the camera

  bool Check(std::string* why) const;
};

// The surface seen through each pixel centre of the undistorted image.
struct SurfaceMap {
  int width = 0, height = 0;
  std::vector<int> surface;  // ids into RenderScene::surfaces, -1 for none; row-major
  std::vector<float> depth;  // metres along the optical axis, 0 for none

  int At(int u, int v) const { return surface[static_cast<size_t>(v) * width + u]; }
  float DepthAt(int u, int v) const { return depth[static_cast<size_t>(v) * width + u]; }
};

// How one frame of a sequence is exposed: the camera's poses over the shutter time (their images
// are averaged: motion blur along the image motion), the gain of the exposure, a covered lens.
struct FrameExposure {
  std::vector<Eigen::Isometry3d> shutter;  // cam_from_world at instants across the shutter time
  double gain = 1.0;     // multiplies the image before the sensor noise (then saturates at 255)
  bool covered = false;  // lens covered: a dark uniform frame with the sensor noise
  int frame_index = 0;   // picks the sensor-noise draw

  bool Check(std::string* why) const;
};

// Renders views of one scene with one camera; keeps its buffers between calls (not thread-safe:
// use one renderer per thread).
class SceneRenderer {
 public:
  // The camera must give the image size. Throws InputError naming the model when the options
  // or the camera are invalid, or clutter is asked without `free_space`.
  SceneRenderer(const WireframeModel& model, const CameraIntrinsics& camera,
                const RenderOptions& options, const NavigableArea* free_space = nullptr);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // The image seen from `cam_from_world` (world -> ViSP camera frame, metres). `frame_index`
  // picks the sensor-noise draw (seeded by the options' seed and the index).
  vpImage<unsigned char> Render(const Eigen::Isometry3d& cam_from_world, int frame_index = 0);

  // One frame of a sequence (throws InputError when the exposure is invalid).
  vpImage<unsigned char> Render(const FrameExposure& exposure);

  // Surfaces that move from frame to frame (people), drawn with the scene until replaced: they
  // follow the scene's own in scene().surfaces.
  void SetMovingSurfaces(const std::vector<RenderSurface>& surfaces);

  // Surface and depth at each pixel centre of the undistorted image, without supersampling
  // (moving surfaces included).
  SurfaceMap RenderSurfaces(const Eigen::Isometry3d& cam_from_world);

  const RenderScene& scene() const;  // the static scene, then the moving surfaces
  const CameraIntrinsics& camera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack

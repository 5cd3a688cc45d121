#include "models/render/scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "models/errors.h"
#include "models/render/frame_decals.h"
#include "models/render/procedural.h"
#include "models/render/zbuffer.h"

namespace linetrack {
namespace {

constexpr double kDecalBias = 1e-4;         // relative depth within which a decal paints
constexpr double kLampRange = 5.0;          // metres: lamp light falls to half at this distance
constexpr double kLampGain = 0.9;           // lamp light of one lamp seen head-on, close
constexpr double kCoarseTextureCell = 0.8;  // metres per lattice cell of the coarse octave
constexpr double kFineTextureCell = 0.2;    // metres per lattice cell of the fine octave
constexpr double kMaxCanvasGrowth = 4.0;    // largest undistorted canvas / image area
constexpr float kBackground = 60.0f;        // grey level where no surface is seen
constexpr int kShadeStep = 4;               // pixels between exact shading evaluations
constexpr float kCoveredLevel = 4.0f;       // grey level of a frame taken with the lens covered

// Pinhole of a grid of samples: sample (i, j) centred at integer coordinates.
struct SampleCamera {
  double px = 1.0, py = 1.0, u0 = 0.0, v0 = 0.0;
  int width = 0, height = 0;
};

// Shading constants of one surface (independent of the view).
struct SurfaceShading {
  Eigen::Vector3d normal, e1, e2;
  double albedo = 0.5;
  double s_offset = 0.0, t_offset = 0.0;  // where the surface reads the noise lattice
  double texture_contrast = 0.0;
};

}  // namespace

struct SceneRenderer::Impl {
  CameraIntrinsics camera;
  RenderOptions options;
  RenderScene scene;
  std::vector<SurfaceShading> shading;
  size_t static_surfaces = 0;  // surfaces of the scene itself; moving ones follow
  ValueNoise noise{0};
  // The undistorted canvas the scene is rendered into before distortion: canvas pixel (x, y)
  // is undistorted pixel (x + canvas_u, y + canvas_v) of the camera.
  int canvas_width = 0, canvas_height = 0;
  double canvas_u = 0.0, canvas_v = 0.0;
  bool distort = false;
  cv::Mat map_x, map_y;  // output pixel -> canvas coordinates

  // Per-view state.
  ZBuffer zbuffer;
  std::vector<Eigen::Vector3d> coeffs;  // inverse depth per surface
  std::vector<char> facing;             // false when a surface's plane is seen edge-on
  Eigen::Matrix3d sample_to_world_dir;  // G: world direction (z_cam = 1) of sample (i, j, 1)
  Eigen::Vector3d centre;               // camera centre (world)
  cv::Mat canvas, blurred, sensor_noise;

  std::vector<uint16_t> row_ids;  // scratch of ShadeCanvas
  std::vector<char> row_uniform;

  void Rasterize(const Eigen::Isometry3d& cam_from_world, const SampleCamera& cam);
  // World point of surface `id` seen through sample (i, j); false when none.
  bool WorldPoint(uint16_t id, double i, double j, Eigen::Vector3d* x) const;
  // Grey level of the textured surface under full light, and the light (<= 1) at x.
  double Reflectance(uint16_t id, const Eigen::Vector3d& x) const;
  double Light(uint16_t id, const Eigen::Vector3d& x) const;
  float Shade(uint16_t id, double i, double j) const;
  // Shades canvas pixels [x_begin, x_end) of row y, all showing surface `id` in every sample.
  void ShadeRun(uint16_t id, int y, int x_begin, int x_end, int k, float* out) const;
  void ShadeCanvas(int k);
  // Shading constants of surface `s` (texture placed from the seed and the id).
  SurfaceShading ShadingOf(size_t s) const;
  // The undistorted canvas seen from `cam_from_world` (rasterised and shaded into `canvas`).
  void RenderCanvas(const Eigen::Isometry3d& cam_from_world);
  // Distortion, blur, gain and sensor noise of a canvas; the 8-bit image.
  vpImage<unsigned char> FormImage(const cv::Mat& canvas_in, double gain, int frame_index);
  // Sizes the undistorted canvas to hold every output pixel's undistorted position, and
  // builds the distortion map (CameraIntrinsics::Undistort of each output pixel).
  void PrepareCanvas();
};

void SceneRenderer::Impl::Rasterize(const Eigen::Isometry3d& cam_from_world,
                                    const SampleCamera& cam) {
  const Eigen::Matrix3d r = cam_from_world.linear();
  const Eigen::Vector3d t = cam_from_world.translation();
  centre = -r.transpose() * t;
  Eigen::Matrix3d k_inv;
  k_inv << 1.0 / cam.px, 0.0, -cam.u0 / cam.px, 0.0, 1.0 / cam.py, -cam.v0 / cam.py, 0.0, 0.0, 1.0;
  sample_to_world_dir = r.transpose() * k_inv;

  const size_t n = scene.surfaces.size();
  coeffs.assign(n, Eigen::Vector3d::Zero());
  facing.assign(n, 0);
  for (size_t s = 0; s < n; ++s) {
    const RenderSurface& surface = scene.surfaces[s];
    // Plane n . X = d in the world: (R n) . X_cam = d - n . C in the camera.
    facing[s] = PlaneInverseDepth(r * surface.normal, surface.offset - surface.normal.dot(centre),
                                  {cam.px, cam.py, cam.u0, cam.v0}, &coeffs[s]);
  }
  zbuffer.Resize(cam.width, cam.height);
  zbuffer.ClearToPlanes(
      facing[kFloorSurface] ? coeffs[kFloorSurface] : Eigen::Vector3d::Zero(), kFloorSurface,
      facing[kCeilingSurface] ? coeffs[kCeilingSurface] : Eigen::Vector3d::Zero(), kCeilingSurface);
  std::vector<Eigen::Vector3d> in_cam;
  std::vector<Eigen::Vector2d> in_samples;
  for (const bool decals : {false, true}) {
    for (size_t s = 2; s < n; ++s) {
      const RenderSurface& surface = scene.surfaces[s];
      if (surface.decal != decals || !facing[s]) continue;
      in_cam.clear();
      for (const Eigen::Vector3d& p : surface.polygon)
        in_cam.push_back(r * p + t);
      in_cam = ClipPolygonNear(in_cam, options.near_clip);
      in_samples.clear();
      for (const Eigen::Vector3d& p : in_cam) {
        in_samples.emplace_back(cam.px * p.x() / p.z() + cam.u0, cam.py * p.y() / p.z() + cam.v0);
      }
      zbuffer.FillPolygon(in_samples, coeffs[s], static_cast<uint16_t>(s),
                          decals ? ZBuffer::Mode::kDecal : ZBuffer::Mode::kNearest,
                          static_cast<float>(kDecalBias));
    }
  }
}

bool SceneRenderer::Impl::WorldPoint(uint16_t id, double i, double j, Eigen::Vector3d* x) const {
  if (id == ZBuffer::kNoSurface) return false;
  const Eigen::Vector3d p(i, j, 1.0);
  const double inv_depth = coeffs[id].dot(p);
  if (!(inv_depth > 0.0)) return false;
  *x = centre + (sample_to_world_dir * p) / inv_depth;
  return true;
}

double SceneRenderer::Impl::Reflectance(uint16_t id, const Eigen::Vector3d& x) const {
  const SurfaceShading& sh = shading[id];
  const double s = sh.e1.dot(x) + sh.s_offset, t = sh.e2.dot(x) + sh.t_offset;
  const double texture = 0.6 * noise(s / kCoarseTextureCell, t / kCoarseTextureCell) +
                         0.4 * noise(s / kFineTextureCell + 97.0, t / kFineTextureCell + 31.0);
  return 255.0 * options.exposure * sh.albedo * (1.0 + sh.texture_contrast * texture);
}

double SceneRenderer::Impl::Light(uint16_t id, const Eigen::Vector3d& x) const {
  const Eigen::Vector3d& normal = shading[id].normal;
  double lamps = 0.0;
  for (const Eigen::Vector3d& lamp : scene.lights) {
    const Eigen::Vector3d to_lamp = lamp - x;
    const double d2 = to_lamp.squaredNorm();
    lamps += std::abs(normal.dot(to_lamp)) / std::sqrt(d2) / (1.0 + d2 / (kLampRange * kLampRange));
  }
  return options.ambient + (1.0 - options.ambient) * std::min(1.0, kLampGain * lamps);
}

float SceneRenderer::Impl::Shade(uint16_t id, double i, double j) const {
  Eigen::Vector3d x;
  if (!WorldPoint(id, i, j, &x)) return kBackground;
  return static_cast<float>(Reflectance(id, x) * Light(id, x));
}

void SceneRenderer::Impl::ShadeRun(uint16_t id, int y, int x_begin, int x_end, int k,
                                   float* out) const {
  // Shading is smooth on a plane (light, texture cells >= several pixels): exact at anchors
  // every kShadeStep pixels and at the run's end, linear in between.
  const double c = 0.5 * (k - 1);
  const double j = k * y + c;
  float previous = Shade(id, k * x_begin + c, j);
  out[x_begin] = previous;
  for (int a = x_begin; a + 1 < x_end;) {
    const int b = std::min(a + kShadeStep, x_end - 1);
    const float next = Shade(id, k * b + c, j);
    const float slope = (next - previous) / static_cast<float>(b - a);
    for (int x = a + 1; x < b; ++x)
      out[x] = previous + slope * static_cast<float>(x - a);
    out[b] = next;
    previous = next;
    a = b;
  }
}

void SceneRenderer::Impl::ShadeCanvas(int k) {
  canvas.create(canvas_height, canvas_width, CV_32F);
  const float inv_samples = 1.0f / static_cast<float>(k * k);
  row_ids.resize(canvas_width);
  row_uniform.resize(canvas_width);
  for (int y = 0; y < canvas_height; ++y) {
    float* out = canvas.ptr<float>(y);
    for (int x = 0; x < canvas_width; ++x) {
      const uint16_t first = zbuffer.id(k * x, k * y);
      bool uniform = true;
      for (int b = 0; b < k && uniform; ++b) {
        const uint16_t* row = zbuffer.id_row(k * y + b) + k * x;
        for (int a = 0; a < k; ++a)
          uniform = uniform && row[a] == first;
      }
      row_ids[x] = first;
      row_uniform[x] = uniform;
    }
    for (int x = 0; x < canvas_width;) {
      if (row_uniform[x]) {
        int end = x + 1;
        while (end < canvas_width && row_uniform[end] && row_ids[end] == row_ids[x])
          ++end;
        ShadeRun(row_ids[x], y, x, end, k, out);
        x = end;
        continue;
      }
      float sum = 0.0f;  // an edge pixel: the mean of its samples
      for (int b = 0; b < k; ++b) {
        for (int a = 0; a < k; ++a) {
          sum += Shade(zbuffer.id(k * x + a, k * y + b), k * x + a, k * y + b);
        }
      }
      out[x] = sum * inv_samples;
      ++x;
    }
  }
}

void SceneRenderer::Impl::PrepareCanvas() {
  distort = options.apply_distortion && camera.has_distortion;
  double u_lo = -0.5, v_lo = -0.5, u_hi = camera.width - 0.5, v_hi = camera.height - 0.5;
  if (distort) {
    // The canvas must hold the undistorted position of every output pixel.
    auto grow = [&](double u, double v) {
      const Eigen::Vector2d p = camera.Undistort({u, v});
      u_lo = std::min(u_lo, p.x());
      u_hi = std::max(u_hi, p.x());
      v_lo = std::min(v_lo, p.y());
      v_hi = std::max(v_hi, p.y());
    };
    for (int u = 0; u < camera.width; ++u)
      grow(u, 0), grow(u, camera.height - 1);
    for (int v = 0; v < camera.height; ++v)
      grow(0, v), grow(camera.width - 1, v);
  }
  canvas_u = distort ? std::floor(u_lo) - 2.0 : 0.0;
  canvas_v = distort ? std::floor(v_lo) - 2.0 : 0.0;
  canvas_width = distort ? static_cast<int>(std::ceil(u_hi) + 3.0 - canvas_u) : camera.width;
  canvas_height = distort ? static_cast<int>(std::ceil(v_hi) + 3.0 - canvas_v) : camera.height;
  if (static_cast<double>(canvas_width) * canvas_height >
      kMaxCanvasGrowth * camera.width * camera.height) {
    throw InputError("camera: the distortion is too strong to render (kdu = " +
                     std::to_string(camera.kdu) + ")");
  }
  if (distort) {
    map_x.create(camera.height, camera.width, CV_32F);
    map_y.create(camera.height, camera.width, CV_32F);
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const Eigen::Vector2d p = camera.Undistort({u, v});
        map_x.at<float>(v, u) = static_cast<float>(p.x() - canvas_u);
        map_y.at<float>(v, u) = static_cast<float>(p.y() - canvas_v);
      }
    }
  }
}

SurfaceShading SceneRenderer::Impl::ShadingOf(size_t s) const {
  const RenderSurface& surface = scene.surfaces[s];
  SurfaceShading sh;
  sh.normal = surface.normal;
  PlaneBasis(surface.normal, &sh.e1, &sh.e2);
  sh.albedo = surface.albedo;
  const uint64_t h = HashCombine(options.scene.seed, s);
  sh.s_offset = 256.0 * kCoarseTextureCell * HashUnit(h);
  sh.t_offset = 256.0 * kCoarseTextureCell * HashUnit(HashMix(h));
  sh.texture_contrast = options.texture_contrast * surface.texture_gain;
  return sh;
}

void SceneRenderer::Impl::RenderCanvas(const Eigen::Isometry3d& cam_from_world) {
  const int k = options.supersample;
  // Sample (i, j) of the supersampled canvas sits at canvas pixel ((i + 0.5) / k - 0.5, ...).
  SampleCamera cam;
  cam.px = k * camera.px;
  cam.py = k * camera.py;
  cam.u0 = k * (camera.u0 - canvas_u + 0.5) - 0.5;
  cam.v0 = k * (camera.v0 - canvas_v + 0.5) - 0.5;
  cam.width = k * canvas_width;
  cam.height = k * canvas_height;
  Rasterize(cam_from_world, cam);
  ShadeCanvas(k);
}

vpImage<unsigned char> SceneRenderer::Impl::FormImage(const cv::Mat& canvas_in, double gain,
                                                      int frame_index) {
  cv::Mat image = canvas_in;
  if (distort) {
    cv::remap(canvas_in, blurred, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    image = blurred.clone();
  }
  if (options.blur_sigma > 0.0) {
    cv::GaussianBlur(image, blurred, cv::Size(0, 0), options.blur_sigma, options.blur_sigma,
                     cv::BORDER_REPLICATE);
    image = blurred;
  }
  if (gain != 1.0) image = image * gain;
  if (options.noise_sigma > 0.0) {
    cv::RNG rng(HashCombine(options.scene.seed, 0x5e4504ull + static_cast<uint64_t>(frame_index)));
    sensor_noise.create(image.size(), CV_32F);
    rng.fill(sensor_noise, cv::RNG::NORMAL, 0.0, options.noise_sigma);
    image = image + sensor_noise;
  }
  cv::Mat grey;
  image.convertTo(grey, CV_8U);  // rounds and saturates
  vpImage<unsigned char> out(static_cast<unsigned>(grey.rows), static_cast<unsigned>(grey.cols));
  for (int v = 0; v < grey.rows; ++v)
    std::memcpy(out[v], grey.ptr<unsigned char>(v), grey.cols);
  return out;
}

bool FrameExposure::Check(std::string* why) const {
  if (shutter.empty() && !covered) {
    *why = "an exposure needs at least one camera pose";
    return false;
  }
  if (!(gain > 0.0 && gain <= 100.0)) {
    *why = "the exposure gain must be in (0, 100]";
    return false;
  }
  return true;
}

bool RenderOptions::Check(std::string* why) const {
  if (!scene.Check(why)) return false;
  if (supersample < 1 || supersample > 4) {
    *why = "supersample must be in [1, 4]";
    return false;
  }
  if (!(noise_sigma >= 0.0 && noise_sigma <= 100.0) || !(blur_sigma >= 0.0 && blur_sigma <= 20.0)) {
    *why = "noise sigma must be in [0, 100] grey levels and blur sigma in [0, 20] pixels";
    return false;
  }
  if (!(texture_contrast >= 0.0 && texture_contrast <= 0.5) ||
      !(ambient >= 0.0 && ambient <= 1.0) || !(exposure > 0.0 && exposure <= 10.0)) {
    *why = "texture_contrast must be in [0, 0.5], ambient in [0, 1], exposure in (0, 10]";
    return false;
  }
  if (!(near_clip > 0.0 && near_clip < 1.0)) {
    *why = "near_clip must be in (0, 1) metres";
    return false;
  }
  return true;
}

SceneRenderer::SceneRenderer(const WireframeModel& model, const CameraIntrinsics& camera,
                             const RenderOptions& options, const NavigableArea* free_space)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!options.Check(&why)) throw InputError(Located(model.path(), 0, "render options: " + why));
  if (!camera.Check(&why)) throw InputError("camera: " + why);
  if (camera.width <= 0 || camera.height <= 0)
    throw InputError("camera: the image size is unknown");
  Impl& m = *impl_;
  m.camera = camera;
  m.options = options;
  m.scene = BuildRenderScene(model, options.scene, free_space);
  if (m.scene.surfaces.size() >= ZBuffer::kNoSurface) {
    throw InputError(Located(model.path(), 0, "too many surfaces to render"));
  }
  m.noise = ValueNoise(HashCombine(options.scene.seed, 0x7e47u));
  m.static_surfaces = m.scene.surfaces.size();
  for (size_t s = 0; s < m.scene.surfaces.size(); ++s)
    m.shading.push_back(m.ShadingOf(s));

  m.PrepareCanvas();
}

SceneRenderer::~SceneRenderer() = default;

const RenderScene& SceneRenderer::scene() const {
  return impl_->scene;
}

const CameraIntrinsics& SceneRenderer::camera() const {
  return impl_->camera;
}

vpImage<unsigned char> SceneRenderer::Render(const Eigen::Isometry3d& cam_from_world,
                                             int frame_index) {
  Impl& m = *impl_;
  m.RenderCanvas(cam_from_world);
  return m.FormImage(m.canvas, 1.0, frame_index);
}

vpImage<unsigned char> SceneRenderer::Render(const FrameExposure& exposure) {
  std::string why;
  if (!exposure.Check(&why)) throw InputError("render: " + why);
  Impl& m = *impl_;
  if (exposure.covered) {
    const cv::Mat dark(m.canvas_height, m.canvas_width, CV_32F, cv::Scalar(kCoveredLevel));
    return m.FormImage(dark, 1.0, exposure.frame_index);
  }
  if (exposure.shutter.size() == 1) {
    m.RenderCanvas(exposure.shutter.front());
    return m.FormImage(m.canvas, exposure.gain, exposure.frame_index);
  }
  cv::Mat sum;
  for (const Eigen::Isometry3d& pose : exposure.shutter) {
    m.RenderCanvas(pose);
    if (sum.empty()) {
      sum = m.canvas.clone();
    } else {
      sum += m.canvas;
    }
  }
  sum *= 1.0 / static_cast<double>(exposure.shutter.size());
  return m.FormImage(sum, exposure.gain, exposure.frame_index);
}

void SceneRenderer::SetMovingSurfaces(const std::vector<RenderSurface>& surfaces) {
  Impl& m = *impl_;
  if (m.static_surfaces + surfaces.size() >= ZBuffer::kNoSurface) {
    throw InputError("render: too many moving surfaces");
  }
  m.scene.surfaces.resize(m.static_surfaces);
  m.shading.resize(m.static_surfaces);
  for (const RenderSurface& surface : surfaces) {
    m.scene.surfaces.push_back(surface);
    m.shading.push_back(m.ShadingOf(m.scene.surfaces.size() - 1));
  }
}

SurfaceMap SceneRenderer::RenderSurfaces(const Eigen::Isometry3d& cam_from_world) {
  Impl& m = *impl_;
  SampleCamera cam;
  cam.px = m.camera.px;
  cam.py = m.camera.py;
  cam.u0 = m.camera.u0;
  cam.v0 = m.camera.v0;
  cam.width = m.camera.width;
  cam.height = m.camera.height;
  m.Rasterize(cam_from_world, cam);
  SurfaceMap map;
  map.width = cam.width;
  map.height = cam.height;
  map.surface.resize(static_cast<size_t>(cam.width) * cam.height);
  map.depth.resize(map.surface.size());
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const uint16_t id = m.zbuffer.id(u, v);
      const float inv_depth = m.zbuffer.inverse_depth(u, v);
      const size_t at = static_cast<size_t>(v) * cam.width + u;
      map.surface[at] = id == ZBuffer::kNoSurface ? -1 : id;
      map.depth[at] = inv_depth > 0.0f ? 1.0f / inv_depth : 0.0f;
    }
  }
  return map;
}

}  // namespace linetrack

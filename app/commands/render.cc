// `linetrack render`: synthetic grey images of a .cao model, one view or a sequence.
//   linetrack render --model M.cao --camera C.xml --pose X,Y,HEADING_DEG --height H --tilt DEG
//                    --out IMG.png [--seed S] [--clutter N] [--noise SIGMA] [--blur SIGMA]
//   linetrack render --model M.cao --camera C.xml (--trajectory TUM.txt | --path hall-loop ...)
//                    --out DIR   -> DIR/frame_%05d.png, groundtruth.txt, priors.csv, camera.xml
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/render/png.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/statistics.h"
#include "models/trajectory_io.h"
#include "models/wireframe.h"

namespace linetrack::app {
namespace {

struct RenderCommandOptions {
  std::string model_path, camera_path, out, nav_path;
  // One view.
  std::string pose;
  double height = 1.3;
  double tilt_deg = 5.0;
  // A sequence.
  std::string trajectory, path;
  int frames = 0;
  double speed = DriveOptions().speed;
  double fps = DriveOptions().fps;
  double pan_amplitude_deg = 0.0, pan_period = DriveOptions().pan_period;
  double tilt_amplitude_deg = 0.0, tilt_period = DriveOptions().tilt_period;
  double wall_distance = LoopPathOptions().wall_distance;
  // Image formation.
  uint64_t seed = 1;
  int clutter = 0;
  double noise = RenderOptions().noise_sigma;
  double blur = RenderOptions().blur_sigma;
  int supersample = RenderOptions().supersample;
  bool undistorted = false;
};

double Milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

bool EndsWithPng(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), ::tolower);
  return name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0;
}

// The camera file as ViSP writes it, placed atomically.
void WriteCameraAtomically(const std::string& path, const CameraIntrinsics& camera) {
  const std::string tmp = path + ".tmp.xml";
  WriteCameraXml(tmp, camera, "<generator>linetrack render</generator>");
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path + ": cannot write the file");
  }
}

RenderOptions ImageOptions(const RenderCommandOptions& opt) {
  RenderOptions options;
  options.scene.seed = opt.seed;
  options.scene.clutter = opt.clutter;
  options.noise_sigma = opt.noise;
  options.blur_sigma = opt.blur;
  options.supersample = opt.supersample;
  options.apply_distortion = !opt.undistorted;
  std::string why;
  if (!options.Check(&why)) throw InputError("render options: " + why);
  return options;
}

// The frames of the sequence form (trajectory file or generated path).
std::vector<SequenceFrame> SequenceFrames(const RenderCommandOptions& opt,
                                          const std::optional<NavigableArea>& area) {
  if (!opt.trajectory.empty()) {
    std::vector<SequenceFrame> frames = FramesFromTrajectory(ReadTum(opt.trajectory));
    if (opt.frames > 0 && static_cast<size_t>(opt.frames) < frames.size())
      frames.resize(opt.frames);
    return frames;
  }
  LoopPathOptions loop_options;
  loop_options.wall_distance = opt.wall_distance;
  DriveOptions drive;
  drive.speed = opt.speed;
  drive.fps = opt.fps;
  drive.frames = opt.frames;
  drive.height = opt.height;
  drive.tilt = DegToRad(opt.tilt_deg);
  drive.tilt_amplitude = DegToRad(opt.tilt_amplitude_deg);
  drive.tilt_period = opt.tilt_period;
  drive.pan_amplitude = DegToRad(opt.pan_amplitude_deg);
  drive.pan_period = opt.pan_period;
  std::string why;
  if (!drive.Check(&why)) throw InputError("--path: " + why);
  return DriveAlongLoop(LoopInsideArea(*area, loop_options), drive);
}

int WriteOneView(const RenderCommandOptions& opt, const RobotPose& pose, SceneRenderer* renderer) {
  const auto start = std::chrono::steady_clock::now();
  const vpImage<unsigned char> image = renderer->Render(CamFromWorld(pose));
  const double ms = Milliseconds(std::chrono::steady_clock::now() - start);
  WriteFileAtomically(opt.out, EncodePng(image));
  std::cout << "wrote " << opt.out << " (" << image.getWidth() << "x" << image.getHeight()
            << ", rendered in " << std::fixed << std::setprecision(1) << ms << " ms)" << std::endl;
  return kExitOk;
}

// DIR/frame_%05d.png, groundtruth.txt (TUM), priors.csv and camera.xml; progress on stderr.
int WriteSequence(const RenderCommandOptions& opt, const std::vector<SequenceFrame>& frames,
                  SceneRenderer* renderer) {
  OdometryOptions odometry;
  odometry.seed = opt.seed;
  const std::vector<PriorRecord> priors = SimulateOdometryPriors(frames, odometry);
  EnsureDirectory(opt.out);
  const std::filesystem::path dir(opt.out);
  std::vector<double> render_ms, total_ms;
  const size_t report_every = std::max<size_t>(1, frames.size() / 10);
  for (size_t f = 0; f < frames.size(); ++f) {
    const auto start = std::chrono::steady_clock::now();
    const vpImage<unsigned char> image =
        renderer->Render(frames[f].cam_from_world, static_cast<int>(f));
    render_ms.push_back(Milliseconds(std::chrono::steady_clock::now() - start));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05zu.png", f);
    WriteFileAtomically((dir / name).string(), EncodePng(image));
    total_ms.push_back(Milliseconds(std::chrono::steady_clock::now() - start));
    if ((f + 1) % report_every == 0 || f + 1 == frames.size()) {
      spdlog::info("rendered {}/{} frames", f + 1, frames.size());
    }
  }
  const CameraIntrinsics& camera = renderer->camera();
  WriteFileAtomically((dir / "groundtruth.txt").string(), FormatTum(GroundTruthPoses(frames)));
  WriteFileAtomically((dir / "priors.csv").string(), FormatPriors(priors));
  WriteCameraAtomically((dir / "camera.xml").string(),
                        opt.undistorted ? camera.Undistorted() : camera);
  std::cout << "wrote " << frames.size() << " frames (" << camera.width << "x" << camera.height
            << ") to " << opt.out << ": median " << std::fixed << std::setprecision(1)
            << QuantileNearestRank(render_ms, 0.5) << " ms per frame to render, "
            << QuantileNearestRank(total_ms, 0.5) << " ms with PNG encoding and writing"
            << std::endl;
  return kExitOk;
}

int RunRender(const RenderCommandOptions& opt) {
  // Flags first (cheap), then files; nothing is written before everything is known to be valid.
  const int forms = !opt.pose.empty() + !opt.trajectory.empty() + !opt.path.empty();
  if (forms != 1) {
    throw InputError("render: give exactly one of --pose, --trajectory, --path");
  }
  const bool single = !opt.pose.empty();
  if (single && !EndsWithPng(opt.out))
    throw InputError("--out: one view is written as a .png file");
  if (!opt.path.empty() && opt.path != "hall-loop") {
    throw InputError("--path: unknown path '" + opt.path + "' (known: hall-loop)");
  }
  const Pose3Dof planar = single ? ParsePrior(opt.pose, "--pose") : Pose3Dof();
  CheckRange(opt.height, 0.0, 100.0, "--height");
  CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  if (opt.frames < 0) throw InputError("--frames: must be >= 0");
  const RenderOptions render_options = ImageOptions(opt);

  const CameraIntrinsics camera = ReadCameraXml(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  const WireframeModel model = WireframeModel::Load(opt.model_path);
  for (const std::string& w : model.warnings())
    spdlog::warn("{}", w);
  std::optional<NavigableArea> area;
  if (opt.clutter > 0 || !opt.path.empty()) {
    NavigableAreaOptions area_options;
    area_options.sidecar_path = opt.nav_path;
    area = NavigableArea::FromModel(model, area_options);
  }
  SceneRenderer renderer(model, camera, render_options, area ? &*area : nullptr);
  if (opt.clutter > renderer.scene().clutter_placed) {
    spdlog::warn("placed {} of {} clutter objects (no room left on the walls)",
                 renderer.scene().clutter_placed, opt.clutter);
  }
  if (renderer.scene().undrawn_lines > 0) {
    spdlog::warn("{} 3D lines lie on no face and are not drawn", renderer.scene().undrawn_lines);
  }

  if (single) {
    const RobotPose pose{planar.x, planar.y, planar.heading, opt.height, DegToRad(opt.tilt_deg)};
    return WriteOneView(opt, pose, &renderer);
  }
  return WriteSequence(opt, SequenceFrames(opt, area), &renderer);
}

}  // namespace

void AddRender(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<RenderCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "render",
      "Synthetic grey images of a .cao model: one view (--pose) or a sequence (--trajectory or "
      "--path) with ground-truth poses, odometry-like priors and the camera file");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model file")->required();
  cmd->add_option("--camera", opt->camera_path,
                  "ViSP camera XML file (with its image size; its distortion is applied)")
      ->required();
  cmd->add_option("--out", opt->out, "Output .png (one view) or folder (sequence)")->required();
  cmd->add_option("--nav", opt->nav_path,
                  "Navigable-area file for clutter and paths (default: MODEL.nav.json)");
  cmd->add_option("--pose", opt->pose, "One view: camera position and heading X,Y,HEADING_DEG");
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)")
      ->capture_default_str();
  cmd->add_option("--tilt", opt->tilt_deg, "Tilt of the optical axis below horizontal (degrees)")
      ->capture_default_str();
  cmd->add_option("--trajectory", opt->trajectory,
                  "Sequence: TUM file 't x y z qx qy qz qw' (camera in world, ViSP axes)");
  cmd->add_option("--path", opt->path, "Sequence: generated path (hall-loop)");
  cmd->add_option("--frames", opt->frames, "Number of frames (default: one lap / whole file)");
  cmd->add_option("--speed", opt->speed, "Robot speed along the path (m/s)")->capture_default_str();
  cmd->add_option("--fps", opt->fps, "Frames per second of the path")->capture_default_str();
  cmd->add_option("--pan-amplitude", opt->pan_amplitude_deg, "Head pan amplitude (degrees)")
      ->capture_default_str();
  cmd->add_option("--pan-period", opt->pan_period, "Head pan period (seconds)")
      ->capture_default_str();
  cmd->add_option("--tilt-amplitude", opt->tilt_amplitude_deg, "Head tilt amplitude (degrees)")
      ->capture_default_str();
  cmd->add_option("--tilt-period", opt->tilt_period, "Head tilt period (seconds)")
      ->capture_default_str();
  cmd->add_option("--wall-distance", opt->wall_distance,
                  "Distance of the generated path from walls and obstacles (metres)")
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of albedos, texture, clutter, noise and odometry")
      ->capture_default_str();
  cmd->add_option("--clutter", opt->clutter, "Unmodelled objects (boxes, cabinets, posters)")
      ->capture_default_str();
  cmd->add_option("--noise", opt->noise, "Sensor noise standard deviation (grey levels)")
      ->capture_default_str();
  cmd->add_option("--blur", opt->blur, "Optical blur standard deviation (pixels)")
      ->capture_default_str();
  cmd->add_option("--supersample", opt->supersample, "Samples per pixel side (1-4)")
      ->capture_default_str();
  cmd->add_flag("--undistorted", opt->undistorted, "Ignore the camera's distortion");
  cmd->callback([opt, action] { *action = [opt] { return RunRender(*opt); }; });
}

}  // namespace linetrack::app

// `linetrack render`: synthetic grey images of a .cao model, one view or a sequence.
//   linetrack render --model M.cao --camera C.xml --pose X,Y,HEADING_DEG --height H --tilt DEG
//                    --out IMG.png [--seed S] [--clutter N] [--noise SIGMA] [--blur SIGMA]
//   linetrack render --model M.cao --camera C.xml (--trajectory TUM.txt | --path hall-loop|FILE)
//                    [effects] [--kidnap FRAME:x,y,heading_deg ...] --out DIR
//     -> DIR/frame_%05d.png, groundtruth.txt, priors.csv, camera.xml, frame_truth.csv,
//        sequence.json
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>

#include "app/commands.h"
#include "app/model_loading.h"
#include "app/render_sequence.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/render/png.h"
#include "models/render/scene_renderer.h"
#include "models/render/waypoint_path.h"
#include "models/trajectory_io.h"
#include "models/wireframe.h"

namespace linetrack::app {
namespace {

// What the command renders; flags that cannot apply to the chosen form are refused.
enum RenderForm : unsigned {
  kView = 1u,        // --pose
  kTrajectory = 2u,  // --trajectory
  kLoop = 4u,        // --path hall-loop
  kWaypoints = 8u,   // --path FILE
};
constexpr unsigned kGenerated = kLoop | kWaypoints;
constexpr unsigned kSequence = kTrajectory | kGenerated;

struct FlagUse {
  const char* flag;
  unsigned forms;
};

// Flags that apply to some forms only (the others apply to all).
constexpr FlagUse kFlagUses[] = {
    {"--height", kView | kGenerated},
    {"--tilt", kView | kGenerated},
    {"--frames", kSequence},
    {"--speed", kGenerated},
    {"--fps", kGenerated},
    {"--pan-amplitude", kGenerated},
    {"--pan-period", kGenerated},
    {"--pan-rate", kGenerated},
    {"--tilt-amplitude", kGenerated},
    {"--tilt-period", kGenerated},
    {"--wall-distance", kLoop},
    {"--corner-radius", kWaypoints},
    {"--people", kSequence},
    {"--blackouts", kSequence},
    {"--blackout-duration", kSequence},
    {"--exposure-changes", kSequence},
    {"--shutter", kSequence},
    {"--odometry-drift", kSequence},
    {"--kidnap", kSequence},
};

std::string FormName(unsigned form) {
  switch (form) {
    case kView:
      return "one view (--pose)";
    case kTrajectory:
      return "--trajectory";
    case kLoop:
      return "--path hall-loop";
    default:
      return "--path FILE";
  }
}

struct RenderCommandOptions {
  std::string model_path, camera_path, out, nav_path;
  std::string pose;  // one view
  double height = 1.3;
  double tilt_deg = 5.0;
  RenderSequenceOptions sequence;
  // Image formation.
  uint64_t seed = 1;
  int clutter = 0;
  double noise = RenderOptions().noise_sigma;
  double blur = RenderOptions().blur_sigma;
  int supersample = RenderOptions().supersample;
  bool undistorted = false;
  std::set<std::string> given;  // the flags on the command line
};

bool EndsWithPng(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), ::tolower);
  return name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0;
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

// The form the flags ask for; throws InputError when none or several, or when a flag cannot
// apply to it.
unsigned ChosenForm(const RenderCommandOptions& opt) {
  const RenderSequenceOptions& s = opt.sequence;
  const int forms = !opt.pose.empty() + !s.trajectory.empty() + !s.path.empty();
  if (forms != 1) throw InputError("render: give exactly one of --pose, --trajectory, --path");
  const unsigned form = !opt.pose.empty()         ? kView
                        : !s.trajectory.empty()   ? kTrajectory
                        : s.path == kHallLoopPath ? kLoop
                                                  : kWaypoints;
  for (const FlagUse& use : kFlagUses) {
    if (opt.given.count(use.flag) > 0 && (use.forms & form) == 0) {
      throw InputError("render: " + std::string(use.flag) + " does not apply to " + FormName(form));
    }
  }
  if (opt.given.count("--pan-rate") > 0 && opt.given.count("--pan-period") > 0) {
    throw InputError(
        "render: give --pan-rate (a constant-rate sweep) or --pan-period (a "
        "sinusoid), not both");
  }
  return form;
}

int WriteOneView(const RenderCommandOptions& opt, const RobotPose& pose, SceneRenderer* renderer) {
  const auto start = std::chrono::steady_clock::now();
  const vpImage<unsigned char> image = renderer->Render(CamFromWorld(pose));
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  WriteFileAtomically(opt.out, EncodePng(image));
  std::cout << "wrote " << opt.out << " (" << image.getWidth() << "x" << image.getHeight()
            << ", rendered in " << std::fixed << std::setprecision(1) << ms << " ms)" << std::endl;
  return kExitOk;
}

int RunRender(RenderCommandOptions opt) {
  // Flags first (cheap), then files; nothing is written before everything is known to be valid.
  const unsigned form = ChosenForm(opt);
  if (form == kView && !EndsWithPng(opt.out))
    throw InputError("--out: one view is written as a .png file");
  const Pose3Dof planar = form == kView ? ParsePrior(opt.pose, "--pose") : Pose3Dof();
  CheckHeight(opt.height, "--height");
  CheckRange(opt.tilt_deg, -89.0, 89.0, "--tilt");
  if (opt.sequence.frames < 0) throw InputError("--frames: must be >= 0");
  opt.sequence.height = opt.height;
  opt.sequence.tilt_deg = opt.tilt_deg;
  opt.sequence.seed = opt.seed;
  opt.sequence.drift_given = opt.given.count("--odometry-drift") > 0;
  CheckSequenceFlags(&opt.sequence);
  const RenderOptions render_options = ImageOptions(opt);

  const CameraIntrinsics camera = LoadCamera(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  const WireframeModel model = LoadModel(opt.model_path);
  std::optional<NavigableArea> area;
  if (opt.clutter > 0 || (form & kGenerated) != 0 || opt.sequence.effects.people > 0) {
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

  if (form == kView) {
    const RobotPose pose{planar.x, planar.y, planar.heading, opt.height, DegToRad(opt.tilt_deg)};
    return WriteOneView(opt, pose, &renderer);
  }
  RenderedSequence sequence = PrepareSequence(opt.sequence, area ? &*area : nullptr);
  WriteSequence(opt.out, model, &renderer, opt.undistorted, &sequence);
  return kExitOk;
}

void AddSequenceFlags(CLI::App* cmd, RenderSequenceOptions* s) {
  cmd->add_option("--trajectory", s->trajectory,
                  "Sequence: TUM file 't x y z qx qy qz qw' (camera in world, ViSP axes)");
  cmd->add_option("--path", s->path,
                  "Sequence: hall-loop (a loop through the navigable area) or a waypoint file "
                  "(lines x,y[,heading_deg])");
  cmd->add_option("--frames", s->frames, "Number of frames (default: one lap / the whole path)");
  cmd->add_option("--speed", s->drive.speed, "Robot speed along the path (m/s)")
      ->capture_default_str();
  cmd->add_option("--fps", s->drive.fps, "Frames per second of the path")->capture_default_str();
  cmd->add_option("--pan-amplitude", s->pan_amplitude_deg, "Head pan amplitude (degrees)")
      ->capture_default_str();
  cmd->add_option("--pan-period", s->drive.pan_period, "Period of a sinusoidal head pan (seconds)")
      ->capture_default_str();
  cmd->add_option("--pan-rate", s->pan_rate_deg,
                  "Head pans at this constant rate (deg/s) between +-amplitude");
  cmd->add_option("--tilt-amplitude", s->tilt_amplitude_deg, "Head tilt amplitude (degrees)")
      ->capture_default_str();
  cmd->add_option("--tilt-period", s->drive.tilt_period, "Head tilt period (seconds)")
      ->capture_default_str();
  cmd->add_option("--wall-distance", s->loop.wall_distance,
                  "hall-loop: distance of the loop from walls and obstacles (metres)")
      ->capture_default_str();
  cmd->add_option("--corner-radius", s->waypoints.corner_radius,
                  "Waypoint path: radius of its rounded corners (metres)")
      ->capture_default_str();
  cmd->add_option("--people", s->effects.people, "People crossing close in front of the camera")
      ->capture_default_str();
  cmd->add_option("--blackouts", s->effects.blackouts, "Times the lens is covered")
      ->capture_default_str();
  cmd->add_option("--blackout-duration", s->effects.blackout_duration,
                  "Seconds the lens stays covered")
      ->capture_default_str();
  cmd->add_option("--exposure-changes", s->effects.exposure_changes,
                  "Gain changes, alternately steps and ramps")
      ->capture_default_str();
  cmd->add_option("--shutter", s->effects.shutter,
                  "Exposure time (seconds): motion blur along the image motion")
      ->capture_default_str();
  cmd->add_option("--odometry-drift", s->odometry_drift_percent,
                  "Odometry drift (percent of the distance travelled; default: the generic "
                  "noise model)");
  cmd->add_option("--kidnap", s->kidnap_texts,
                  "FRAME:x,y,heading_deg: the robot is carried and put down there (the base) on "
                  "FRAME, its odometry blind to the carry (repeatable)");
}

}  // namespace

void AddRender(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<RenderCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "render",
      "Synthetic grey images of a .cao model: one view (--pose) or a sequence (--trajectory or "
      "--path) with ground-truth poses, odometry-like priors, per-frame truth and the camera file");
  cmd->add_option("--model", opt->model_path, "ViSP .cao model file")->required();
  cmd->add_option("--camera", opt->camera_path,
                  "ViSP camera XML file (with its image size; its distortion is applied)")
      ->required();
  cmd->add_option("--out", opt->out, "Output .png (one view) or folder (sequence)")->required();
  cmd->add_option("--nav", opt->nav_path,
                  "Navigable-area file for clutter, paths and people (default: MODEL.nav.json)");
  cmd->add_option("--pose", opt->pose, "One view: camera position and heading X,Y,HEADING_DEG");
  cmd->add_option("--height", opt->height, "Camera height above the floor (metres)")
      ->capture_default_str();
  cmd->add_option("--tilt", opt->tilt_deg, "Tilt of the optical axis below horizontal (degrees)")
      ->capture_default_str();
  AddSequenceFlags(cmd, &opt->sequence);
  cmd->add_option("--seed", opt->seed,
                  "Seed of albedos, texture, clutter, noise, odometry and effects")
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
  cmd->callback([opt, action, cmd] {
    for (const CLI::Option* option : cmd->get_options()) {
      if (option->count() > 0 && !option->get_lnames().empty()) {
        opt->given.insert("--" + option->get_lnames().front());
      }
    }
    *action = [opt] { return RunRender(*opt); };
  });
}

}  // namespace linetrack::app

#include "tracking/sim/sim_camera.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "models/render/sequence.h"
#include "tracking/head/head_pointing.h"

namespace linetrack {
namespace {

double HostSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// A finite number from `text`, or an InputError naming the argument.
double ParseNumber(const std::string& text, const std::string& key, const std::string& where) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  throw InputError(where + ": " + key + " needs a finite number, got '" + text + "'");
}

// Three finite numbers "A:B:C" from `text`, or an InputError naming the argument.
Eigen::Vector3d ParseTriple(const std::string& text, const std::string& key,
                            const std::string& where) {
  Eigen::Vector3d v;
  size_t begin = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t end = k < 2 ? text.find(':', begin) : text.size();
    if (end == std::string::npos) {
      throw InputError(where + ": " + key + " needs three numbers A:B:C, got '" + text + "'");
    }
    v[k] = ParseNumber(text.substr(begin, end - begin), key, where);
    begin = end + 1;
  }
  return v;
}

}  // namespace

bool SimCameraOptions::Check(std::string* why) const {
  if (!(fps > 0.0 && fps <= 1000.0)) {
    *why = "fps must be in (0, 1000]";
    return false;
  }
  if (!(speed > 0.0 && speed <= 20.0)) {
    *why = "speed must be in (0, 20] m/s";
    return false;
  }
  if (!(wall_distance > 0.0 && wall_distance < 100.0)) {
    *why = "wall distance must be in (0, 100) m";
    return false;
  }
  if (!(camera_height > 0.0 && camera_height < 100.0)) {
    *why = "camera height must be in (0, 100) m";
    return false;
  }
  if (!std::isfinite(still_base.x) || !std::isfinite(still_base.y) ||
      !std::isfinite(still_base.heading)) {
    *why = "the base pose must be finite";
    return false;
  }
  if (!(bracket_error.head<3>().norm() < 0.1) || !(bracket_error.tail<3>().norm() < 0.5)) {
    *why = "the bracket's error must be under 0.1 m and 0.5 rad";
    return false;
  }
  if (!std::isfinite(cap_from_s) || !std::isfinite(cap_to_s)) {
    *why = "the cap interval must be finite";
    return false;
  }
  return render_options.Check(why);
}

void ParseSimArguments(const std::string& arguments, SimCameraOptions* options) {
  const std::string where = "--source sim:" + arguments;
  if (arguments.empty()) return;
  std::stringstream in(arguments);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw InputError(where + ": expected key=value, got '" + item + "'");
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "path") {
      if (value == "still") {
        options->path = SimPath::kStill;
      } else if (value == "loop") {
        options->path = SimPath::kLoop;
      } else {
        throw InputError(where + ": path must be still or loop, got '" + value + "'");
      }
    } else if (key == "fps") {
      options->fps = ParseNumber(value, key, where);
    } else if (key == "speed") {
      options->speed = ParseNumber(value, key, where);
    } else if (key == "seed") {
      const double seed = ParseNumber(value, key, where);
      if (seed < 0 || seed != std::floor(seed) || seed > 1e15) {
        throw InputError(where + ": seed must be a whole number >= 0");
      }
      options->render_options.scene.seed = static_cast<uint64_t>(seed);
      options->odometry_seed = static_cast<uint64_t>(seed);
    } else if (key == "clutter") {
      const double clutter = ParseNumber(value, key, where);
      if (clutter < 0 || clutter != std::floor(clutter) || clutter > 1000) {
        throw InputError(where + ": clutter must be a whole number in [0, 1000]");
      }
      options->render_options.scene.clutter = static_cast<int>(clutter);
    } else if (key == "noise") {
      options->render_options.noise_sigma = ParseNumber(value, key, where);
    } else if (key == "blur") {
      options->render_options.blur_sigma = ParseNumber(value, key, where);
    } else if (key == "cap") {
      const size_t dash = value.find('-', 1);
      if (dash == std::string::npos) {
        throw InputError(where + ": cap must be T0-T1 (seconds), got '" + value + "'");
      }
      options->cap_from_s = ParseNumber(value.substr(0, dash), key, where);
      options->cap_to_s = ParseNumber(value.substr(dash + 1), key, where);
      if (!(options->cap_to_s > options->cap_from_s)) {
        throw InputError(where + ": cap must be T0-T1 with T1 > T0, got '" + value + "'");
      }
    } else if (key == "bracket_mm") {
      options->bracket_error.head<3>() = 1e-3 * ParseTriple(value, key, where);
    } else if (key == "bracket_deg") {
      options->bracket_error.tail<3>() = DegToRad(1.0) * ParseTriple(value, key, where);
    } else if (key == "render") {
      if (value != "0" && value != "1") throw InputError(where + ": render must be 0 or 1");
      options->render = value == "1";
    } else {
      throw InputError(where + ": unknown key '" + key +
                       "' (known: path, fps, speed, seed, clutter, noise, blur, cap, render, "
                       "bracket_mm, bracket_deg)");
    }
  }
  std::string why;
  if (!options->Check(&why)) throw InputError(where + ": " + why);
}

SimulatedCamera::SimulatedCamera(const WireframeModel& model, const NavigableArea* area,
                                 const CameraIntrinsics& camera, const SimCameraOptions& options)
    : options_(options), camera_(camera) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("simulated camera: " + why);
  if (camera_.width <= 0 || camera_.height <= 0) {
    throw InputError("simulated camera: the camera gives no image size");
  }
  geometry_ = GeometryOf(options_.head_model);
  geometry_.tilt_from_camera = MovedPose(geometry_.tilt_from_camera, options_.bracket_error);
  crossing_height_ = CrossingHeightFor(geometry_, options_.camera_height);
  if (options_.render) {
    renderer_ = std::make_unique<SceneRenderer>(model, camera_, options_.render_options, area);
  }
  if (options_.path == SimPath::kLoop) {
    if (area == nullptr) throw InputError("simulated camera: the loop needs the navigable area");
    LoopPathOptions loop_options;
    loop_options.wall_distance = options_.wall_distance;
    DriveOptions drive;
    drive.speed = options_.speed;
    drive.fps = options_.fps;
    drive.height = options_.camera_height;
    drive.tilt = 0.0;
    const std::vector<SequenceFrame> lap =
        DriveAlongLoop(LoopInsideArea(*area, loop_options), drive);
    OdometryOptions odometry;
    odometry.seed = options_.odometry_seed;
    const std::vector<PriorRecord> priors = SimulateOdometryPriors(lap, odometry);
    for (size_t k = 0; k < lap.size(); ++k) {
      loop_bases_.push_back(lap[k].base.Planar());
      loop_odometry_.push_back(priors[k].pose.Planar());
    }
  }
}

SimulatedCamera::~SimulatedCamera() = default;

int SimulatedCamera::LoopIndexAt(double t) const {
  const long k = std::lround(t * options_.fps);
  const long n = static_cast<long>(loop_bases_.size());
  return static_cast<int>(((k % n) + n) % n);
}

Pose3Dof SimulatedCamera::BaseAt(double t) const {
  if (options_.path == SimPath::kStill) return options_.still_base;
  return loop_bases_[LoopIndexAt(t)];
}

Pose3Dof SimulatedCamera::OdometryAt(double t) const {
  if (options_.path == SimPath::kStill) return options_.still_base;
  return loop_odometry_[LoopIndexAt(t)];
}

bool SimulatedCamera::CappedAt(double t) const {
  return t >= options_.cap_from_s && t < options_.cap_to_s;
}

void SimulatedCamera::AttachHead(SimulatedHead* head) {
  AttachHead(head, [head](double dt) { head->Step(dt); });
}

void SimulatedCamera::AttachHead(PanTiltHead* head, std::function<void(double)> advance) {
  head_ = head;
  advance_head_ = std::move(advance);
}

std::string SimulatedCamera::LastError() const {
  if (head_ == nullptr) return "no head attached";
  return last_error_;
}

FrameStatus SimulatedCamera::Grab(Frame* frame) {
  if (head_ == nullptr) return FrameStatus::kDeviceLost;
  const double period = 1.0 / options_.fps;
  if (head_clock_index_ < next_index_) {  // once per frame, even when a read fails
    advance_head_(period);
    head_clock_index_ = next_index_;
  }
  const double t = next_index_ * period;
  HeadState state;
  const HeadResult read = head_->Read(&state);
  if (!read.ok()) {
    last_error_ = "head read failed: " + read.message;
    ++stats_.losses;
    return FrameStatus::kDeviceLost;
  }
  last_error_.clear();
  last_time_ = t;
  last_pan_ = state.pan;
  last_tilt_ = state.tilt;
  last_cam_from_world_ =
      CamFromWorldOnHead(geometry_, BaseAt(t), crossing_height_, state.pan, state.tilt);
  last_capped_ = CappedAt(t);
  if (last_capped_) {
    frame->image.resize(camera_.height, camera_.width, 0);
  } else if (renderer_) {
    frame->image = renderer_->Render(last_cam_from_world_, static_cast<int>(next_index_));
  } else {
    frame->image.resize(camera_.height, camera_.width, 128);
  }
  frame->timestamp_s = t;
  frame->has_camera_timestamp = true;
  frame->host_time_s = HostSeconds();
  frame->frame_id = static_cast<std::uint64_t>(next_index_);
  frame->index = next_index_;
  ++next_index_;
  ++stats_.delivered;
  return FrameStatus::kOk;
}

std::string SimulatedCamera::Describe() const {
  std::ostringstream out;
  out << "sim (" << camera_.width << "x" << camera_.height << ", " << options_.fps
      << " frames/s simulated, "
      << (options_.path == SimPath::kStill ? "base standing still" : "base driving the loop")
      << (renderer_ ? ", rendered" : ", not rendered") << ")";
  return out.str();
}

}  // namespace linetrack

namespace linetrack {

bool PoseJitterOptions::Check(std::string* why) const {
  if (!(rotation_sigma >= 0.0 && rotation_sigma < 0.5) ||
      !(translation_sigma >= 0.0 && translation_sigma < 10.0)) {
    *why = "pose jitter must be in [0, 0.5) rad and [0, 10) m";
    return false;
  }
  return true;
}

SimulatorTruthEstimator::SimulatorTruthEstimator(const SimulatedCamera* camera,
                                                 const PoseJitterOptions& jitter)
    : camera_(camera), jitter_(jitter), rng_(jitter.seed) {
  std::string why;
  if (!jitter_.Check(&why)) throw InputError("simulator truth: " + why);
}

PoseEstimate SimulatorTruthEstimator::Estimate(const Frame& frame, const HeadState& /*head*/,
                                               const RobotPose& /*camera_prior*/) {
  PoseEstimate estimate;
  estimate.source = "simulator truth";
  if (frame.frame_id != static_cast<std::uint64_t>(frame.index) ||
      frame.timestamp_s != camera_->last_time()) {
    estimate.status = had_pose_ ? PoseStatus::kLost : PoseStatus::kInitialising;
    estimate.note = "the frame is not the simulator's last one";
    lost_ = had_pose_;
    return estimate;
  }
  if (camera_->last_capped()) {
    estimate.status = had_pose_ ? PoseStatus::kLost : PoseStatus::kInitialising;
    estimate.note = "lens capped";
    lost_ = had_pose_;
    return estimate;
  }
  estimate.status = lost_ ? PoseStatus::kRelocalised : PoseStatus::kTracking;
  Eigen::Isometry3d pose = camera_->last_cam_from_world();
  if (jitter_.rotation_sigma > 0.0 || jitter_.translation_sigma > 0.0) {
    std::normal_distribution<double> r(0.0, jitter_.rotation_sigma);
    std::normal_distribution<double> t(0.0, jitter_.translation_sigma);
    const Eigen::Vector3d w(r(rng_), r(rng_), r(rng_));
    Eigen::Isometry3d noise = Eigen::Isometry3d::Identity();
    if (w.norm() > 0.0)
      noise.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    noise.translation() = Eigen::Vector3d(t(rng_), t(rng_), t(rng_));
    pose = noise * pose;
  }
  estimate.cam_from_world = pose;
  // The truth (with its stated jitter): its covariance the jitter's, its protection levels five
  // sigmas (chi2(3) beyond 25: 1.5e-5).
  estimate.uncertainty.status = IntegrityStatus::kTracking;
  estimate.uncertainty.world_covariance.setZero();
  estimate.uncertainty.world_covariance.diagonal()
      << Eigen::Vector3d::Constant(jitter_.translation_sigma * jitter_.translation_sigma),
      Eigen::Vector3d::Constant(jitter_.rotation_sigma * jitter_.rotation_sigma);
  estimate.uncertainty.sigma_x_m = estimate.uncertainty.sigma_y_m = jitter_.translation_sigma;
  estimate.uncertainty.sigma_heading_rad = jitter_.rotation_sigma;
  estimate.uncertainty.protection_position_m = 5.0 * jitter_.translation_sigma;
  estimate.uncertainty.protection_rotation_rad = 5.0 * jitter_.rotation_sigma;
  had_pose_ = true;
  lost_ = false;
  return estimate;
}

}  // namespace linetrack

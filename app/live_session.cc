#include "app/live_session.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>
#include <thread>

#include "app/head_mount.h"
#include "models/errors.h"
#include "tracking/capture/source_factory.h"
#include "tracking/head/head_factory.h"
#include "tracking/head/head_pointing.h"

namespace linetrack::app {
namespace {

// Moves a real head to (pan, tilt) and waits until it stops there (20 s at most).
void MoveHeadAndWait(PanTiltHead* head, double pan, double tilt) {
  const HeadResult moved = head->MoveTo(pan, tilt);
  if (!moved.ok()) throw std::runtime_error("head: cannot move to the start: " + moved.message);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (true) {
    HeadState state;
    const HeadResult read = head->Read(&state);
    if (!read.ok()) throw std::runtime_error("head: " + read.message);
    if (!state.moving) return;
    if (std::chrono::steady_clock::now() > deadline) {
      throw std::runtime_error("head: still moving to the start after 20 s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace

Pose3Dof PriorAt(const std::vector<PriorRecord>& priors, double t) {
  if (priors.empty()) throw InputError("--prior-file: no rows");
  constexpr double kTimeToleranceS = 1e-3;  // files round their times (6 decimals in ours)
  size_t k = 0;
  while (k + 1 < priors.size() && priors[k + 1].t <= t + kTimeToleranceS)
    ++k;
  return priors[k].pose.Planar();
}

LiveSession::LiveSession(const LivePlan& plan, const LiveInputs& inputs) {
  const BelievedHead believed =
      BelieveHead(plan.head_model, inputs.mount, inputs.mount_path, plan.height);
  mount_ = believed.description;
  LiveLoopOptions loop = plan.loop;
  loop.servo.geometry = believed.geometry;
  loop.crossing_height = believed.crossing_height;
  if (plan.use_tracker) {
    if (inputs.area == nullptr) throw InputError("live: the tracker needs the navigable area");
    tracker_ = std::make_unique<TrackerPoseEstimator>(*inputs.model, *inputs.area, inputs.camera,
                                                      inputs.tracker);
  }
  if (plan.sim) {
    SimulatedHeadOptions head;
    SimHeadStart start;
    if (plan.head_start) {
      head.initial_pan = plan.head_start->x();
      head.initial_tilt = plan.head_start->y();
      std::string why;
      if (!head.Check(&why)) throw InputError("--head-start: " + why);
    }
    start.offset_from_target = plan.head_start_offset;
    rig_ = std::make_unique<SimulatedLiveRig>(
        *inputs.model, inputs.area, inputs.camera,
        SimulatedLiveRigOptions{plan.sim_camera, head, loop, start, PoseJitterOptions{}},
        tracker_.get());
    return;
  }
  OpenDevices(plan, loop, inputs);
}

void LiveSession::OpenDevices(const LivePlan& plan, const LiveLoopOptions& loop,
                              const LiveInputs& inputs) {
  // Cameras are set to the calibrated image size (and frame rate when asked).
  FrameSourceOptions sources;
  sources.aravis.width = inputs.camera.width;
  sources.aravis.height = inputs.camera.height;
  sources.aravis.frame_rate = plan.camera_fps;
  sources.aravis.latest_only = true;  // the servo acts on the newest frame, never a backlog
  source_ = OpenFrameSource(plan.source_spec, sources);
  head_ = OpenHead(plan.head_spec, HeadOptions{});
  const HeadGeometry& geometry = loop.servo.geometry;
  const double crossing = loop.crossing_height;
  const Pose3Dof base = plan.prior ? *plan.prior : PriorAt(inputs.priors, 0.0);
  if (plan.head_start) MoveHeadAndWait(head_.get(), plan.head_start->x(), plan.head_start->y());
  if (plan.head_start_offset) {
    double pan = 0.0, tilt = 0.0;
    if (!HeadAnglesLookingAt(geometry, WorldFromHeadBase(geometry, base, crossing), *loop.target,
                             &pan, &tilt)) {
      throw InputError("--head-start-offset: the target is too close to the head to look at");
    }
    MoveHeadAndWait(head_.get(), pan + plan.head_start_offset->x(),
                    tilt + plan.head_start_offset->y());
  }
  BaseOdometry odometry;
  if (plan.prior) {
    odometry = [base](double) { return base; };
  } else {
    // Prior-file times count from the first frame.
    auto first_t = std::make_shared<std::optional<double>>();
    const std::vector<PriorRecord> priors = inputs.priors;
    odometry = [first_t, priors](double t) {
      if (!*first_t) *first_t = t;
      return PriorAt(priors, t - **first_t);
    };
  }
  loop_ = std::make_unique<LiveLoop>(
      LiveLoopParts{source_.get(), head_.get(), tracker_.get(), odometry}, *inputs.model,
      inputs.camera.Undistorted(), loop);
}

LiveSession::~LiveSession() = default;

std::string LiveSession::DescribeSource() const {
  return rig_ ? rig_->camera().Describe() : source_->Describe();
}

std::string LiveSession::DescribeHead() const {
  return rig_ ? rig_->head().Describe() : head_->Describe();
}

std::string LiveSession::DescribeEstimator() const {
  return rig_ ? rig_->estimator().Describe() : tracker_->Describe();
}

const Eigen::Isometry3d* LiveSession::truth() const {
  return rig_ ? &rig_->camera().last_cam_from_world() : nullptr;
}

}  // namespace linetrack::app

#include "tracking/live/live_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "models/errors.h"
#include "models/text_format.h"
#include "tracking/head/head_pointing.h"

namespace linetrack {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::optional<Eigen::Vector3d> VisibleModelCentroid(const WireframeModel& model,
                                                    const OcclusionTester& occlusion,
                                                    const Eigen::Isometry3d& cam_from_world,
                                                    const CameraIntrinsics& camera) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double length = 0.0;
  for (const ProjectedEdge& edge : ProjectVisibleEdges(model, occlusion, cam_from_world, camera)) {
    const double l = edge.world.Length();
    sum += l * 0.5 * (edge.world.a + edge.world.b);
    length += l;
  }
  if (!(length > 0.0)) return std::nullopt;
  return sum / length;
}

bool LiveLoopOptions::Check(std::string* why) const {
  if (!servo.Check(why)) return false;
  if (target && !target->allFinite()) {
    *why = "the target must be finite";
    return false;
  }
  if (desired_px && !desired_px->allFinite()) {
    *why = "the target pixel must be finite";
    return false;
  }
  if (!(std::abs(crossing_height) < 100.0)) {
    *why = "the head's height must be within 100 m";
    return false;
  }
  return true;
}

const char* ToString(HeadCommand command) {
  switch (command) {
    case HeadCommand::kNone:
      return "none";
    case HeadCommand::kVelocity:
      return "velocity";
    case HeadCommand::kHold:
      return "hold";
    case HeadCommand::kStop:
      return "stop";
  }
  return "unknown";
}

LiveLoop::LiveLoop(LiveLoopParts parts, const WireframeModel& model, const CameraIntrinsics& camera,
                   const LiveLoopOptions& options)
    : source_(parts.source),
      head_(parts.head),
      estimator_(parts.estimator),
      odometry_(std::move(parts.odometry)),
      model_(model),
      occlusion_(model),
      camera_(camera),
      options_(options),
      geometry_(options.servo.geometry),
      limits_(head_->Limits()),
      servo_(options.servo),
      target_(options.target) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("live loop: " + why);
  if (camera_.width <= 0 || camera_.height <= 0) {
    throw InputError("live loop: the camera gives no image size");
  }
  desired_px_ = options_.desired_px.value_or(Eigen::Vector2d(camera_.u0, camera_.v0));
  if (!camera_.Contains(desired_px_)) {
    throw InputError("live loop: the target pixel is outside the image");
  }
}

HeadResult LiveLoop::SafeStop() {
  const HeadResult r = head_->Stop();
  if (r.ok()) stopped_ = true;
  return r;
}

void LiveLoop::StopHead(const std::string& why, LiveIteration* it) {
  servo_.Reset();
  it->note = why;
  if (stopped_) return;  // already still: nothing to send
  it->command = HeadCommand::kStop;
  it->command_result = SafeStop();
  if (!it->command_result.ok()) it->head_error = true;
}

void LiveLoop::Command(const ServoStep& step, LiveIteration* it) {
  if (step.converged) {
    if (stopped_) return;
    it->command = HeadCommand::kHold;
    it->command_result = head_->SetVelocity(0.0, 0.0);
    stopped_ = it->command_result.ok();
    if (!stopped_) it->head_error = true;
    return;
  }
  it->command = HeadCommand::kVelocity;
  it->command_result = head_->SetVelocity(step.pan_rate, step.tilt_rate);
  stopped_ = it->command_result.ok() && step.pan_rate == 0.0 && step.tilt_rate == 0.0;
  if (!it->command_result.ok()) {
    // The head may still follow the previous command: stop it rather than let it run.
    it->head_error = true;
    it->note = "velocity command failed: " + it->command_result.message;
    servo_.Reset();
    const HeadResult stop = SafeStop();
    if (stop.ok()) {
      it->command = HeadCommand::kStop;
      it->command_result = stop;
    }
  }
}

LiveIteration LiveLoop::Step() {
  LiveIteration it;
  const Clock::time_point grab_start = Clock::now();
  it.grab = source_->Grab(&frame_);
  it.grab_ms = MillisecondsSince(grab_start);
  const Clock::time_point start = Clock::now();
  if (it.grab != FrameStatus::kOk) {
    if (it.grab != FrameStatus::kEndOfStream) {
      StopHead(std::string("no frame: ") + ToString(it.grab), &it);
    }
    it.loop_ms = MillisecondsSince(start);
    return it;
  }
  it.frame = frame_.index;
  it.t = frame_.timestamp_s;
  if (static_cast<int>(frame_.image.getWidth()) != camera_.width ||
      static_cast<int>(frame_.image.getHeight()) != camera_.height) {
    StopHead("frame " + std::to_string(frame_.image.getWidth()) + "x" +
                 std::to_string(frame_.image.getHeight()) + " but the camera is " +
                 std::to_string(camera_.width) + "x" + std::to_string(camera_.height),
             &it);
    it.loop_ms = MillisecondsSince(start);
    return it;
  }

  const HeadResult read = head_->Read(&it.head);
  it.head_read = read.ok();
  if (!it.head_read) {
    it.head_error = true;
    StopHead("head read failed: " + read.message, &it);
    it.loop_ms = MillisecondsSince(start);
    return it;
  }
  it.camera_prior = CameraPoseOnHead(geometry_, odometry_(it.t), options_.crossing_height,
                                     it.head.pan, it.head.tilt);

  const Clock::time_point estimate_start = Clock::now();
  it.estimate = estimator_->Estimate(frame_, it.head, it.camera_prior);
  it.estimate_ms = MillisecondsSince(estimate_start);
  if (!it.estimate.has_pose()) {
    StopHead("no pose: " + it.estimate.note, &it);
    it.loop_ms = MillisecondsSince(start);
    return it;
  }
  const Eigen::Isometry3d& cam_from_world = *it.estimate.cam_from_world;
  if (!target_) target_ = VisibleModelCentroid(model_, occlusion_, cam_from_world, camera_);
  if (!target_) {
    StopHead("no target: no model edge visible for the centroid", &it);
    it.loop_ms = MillisecondsSince(start);
    return it;
  }
  it.has_target = true;
  it.target = *target_;
  it.servo = servo_.Compute(it.t, cam_from_world * *target_, desired_px_, camera_,
                            HeadJoints{it.head.pan, it.head.tilt, limits_});
  if (!it.servo.ok) {
    StopHead("servo: " + it.servo.reason, &it);
  } else {
    Command(it.servo, &it);
  }
  it.loop_ms = MillisecondsSince(start);
  return it;
}

void LiveSummary::Add(const LiveIteration& it) {
  ++iterations;
  if (it.grab == FrameStatus::kTimeout) ++timeouts;
  if (it.grab == FrameStatus::kDeviceLost) ++device_lost;
  if (it.command == HeadCommand::kStop) ++stops;
  if (it.head_error) ++head_errors;
  if (it.grab != FrameStatus::kOk) return;
  if (frames == 0) {
    start_t = it.t;
  }
  ++frames;
  last_t = it.t;
  loop_ms.push_back(it.loop_ms);
  if (it.head_read) {
    const bool first = frames == 1;
    pan_min = first ? it.head.pan : std::min(pan_min, it.head.pan);
    pan_max = first ? it.head.pan : std::max(pan_max, it.head.pan);
    tilt_min = first ? it.head.tilt : std::min(tilt_min, it.head.tilt);
    tilt_max = first ? it.head.tilt : std::max(tilt_max, it.head.tilt);
  }
  const bool had_pose_before = with_pose > 0;
  if (it.estimate.has_pose()) {
    if (had_pose_before && in_loss) ++recoveries;
    in_loss = false;
    ++with_pose;
  } else {
    if (had_pose_before && !in_loss) ++losses;
    if (had_pose_before) in_loss = true;
    ++without_pose;
  }
  if (!it.servo.ok) return;
  if (it.servo.converged) {
    ++converged_frames;
    if (first_convergence_t < 0.0) first_convergence_t = it.t;
  }
  if (first_convergence_t >= 0.0) {
    max_error_after_convergence_px = std::max(max_error_after_convergence_px, it.servo.error_px);
  }
  final_error_px = it.servo.error_px;
  if (it.servo.saturated) ++saturated_frames;
  if (it.servo.limited) ++limited_frames;
  max_abs_pan_rate = std::max(max_abs_pan_rate, std::abs(it.servo.pan_rate));
  max_abs_tilt_rate = std::max(max_abs_tilt_rate, std::abs(it.servo.tilt_rate));
}

}  // namespace linetrack

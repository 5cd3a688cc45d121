#include "app/bench/servo_bench.h"

#include <algorithm>
#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/statistics.h"
#include "tracking/head/head_pointing.h"
#include "tracking/sim/sim_rig.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack::app {
namespace {

constexpr double kConvergedPx = 2.0;

// `tracker` (null with the simulator's truth) is the rig's estimator, for its stage times.
ServoBenchRun RunOne(const std::string& name, SimulatedLiveRig* rig,
                     const TrackerPoseEstimator* tracker, int frames, double settle_seconds) {
  ServoBenchRun run;
  run.name = name;
  run.settle_s = settle_seconds;
  std::vector<double> settled;
  for (int k = 0; k < frames; ++k) {
    const LiveIteration it = rig->loop().Step();
    if (it.grab != FrameStatus::kOk) continue;
    ++run.frames;
    run.loop_ms.push_back(it.loop_ms);
    run.estimate_ms.push_back(it.estimate_ms);
    run.grab_ms.push_back(it.grab_ms);
    if (tracker) {
      const FrameReport& report = tracker->last_report();
      run.undistort_ms.push_back(report.undistort_ms);
      run.predict_ms.push_back(report.predict_ms);
      run.passes_ms.push_back(report.passes_ms);
      run.measure_ms.push_back(report.measure_ms);
      run.relocalize_ms.push_back(report.relocalize_ms);
      run.tracking_passes += report.health.passes;
    }
    if (it.estimate.has_pose()) {
      ++run.frames_with_pose;
      const PoseDifference d =
          ComparePoses(*it.estimate.cam_from_world, rig->camera().last_cam_from_world());
      run.max_position_error_m = std::max(run.max_position_error_m, d.translation);
      run.max_rotation_error_deg = std::max(run.max_rotation_error_deg, RadToDeg(d.rotation));
    }
    const double error = rig->TrueErrorPx();
    if (k == 0) run.start_error_px = error;
    if (run.convergence_s < 0.0 && error >= 0.0 && error < kConvergedPx) run.convergence_s = it.t;
    run.final_error_px = error;
    if (it.t >= settle_seconds) settled.push_back(error);
  }
  if (!settled.empty()) {
    double sum = 0.0;
    for (double e : settled)
      sum += e;
    run.mean_error_px = sum / settled.size();
    run.p95_error_px = QuantileNearestRank(settled, 0.95);
    run.max_error_px = *std::max_element(settled.begin(), settled.end());
  }
  return run;
}

}  // namespace

bool ServoBenchOptions::Check(std::string* why) const {
  if (!(fps > 0.0 && fps <= 1000.0)) {
    *why = "fps must be in (0, 1000]";
    return false;
  }
  if (!(still_seconds >= 0.0 && drive_seconds >= 0.0 && still_seconds + drive_seconds > 0.0 &&
        still_seconds < 1e5 && drive_seconds < 1e5)) {
    *why = "run lengths must be >= 0 s, not both 0";
    return false;
  }
  if (use_tracker && !render) {
    *why = "the tracker needs rendered frames";
    return false;
  }
  if (!(settle_seconds >= 0.0)) {
    *why = "settle time must be >= 0 s";
    return false;
  }
  return servo.Check(why) && jitter.Check(why);
}

std::vector<ServoBenchRun> RunServoBench(const WireframeModel& model, const NavigableArea& area,
                                         const CameraIntrinsics& camera,
                                         const ServoBenchOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError("bench servo: " + why);
  SimCameraOptions sim;
  sim.fps = options.fps;
  sim.render = options.render;
  LiveLoopOptions loop;
  loop.servo = options.servo;
  loop.crossing_height = CrossingHeightFor(loop.servo.geometry, sim.camera_height);
  // A fresh tracker per run (null: the simulator's truth).
  auto MakeTracker = [&]() -> std::unique_ptr<TrackerPoseEstimator> {
    if (!options.use_tracker) return nullptr;
    return std::make_unique<TrackerPoseEstimator>(model, area, camera, options.tracker);
  };
  std::vector<ServoBenchRun> runs;
  if (options.still_seconds > 0.0) {
    sim.path = SimPath::kStill;
    sim.still_base = options.still_base;
    loop.target = options.still_target;
    SimHeadStart start;
    start.offset_from_target = Eigen::Vector2d(options.start_pan_offset, options.start_tilt_offset);
    const auto tracker = MakeTracker();
    SimulatedLiveRig rig(
        model, &area, camera,
        SimulatedLiveRigOptions{sim, SimulatedHeadOptions{}, loop, start, options.jitter},
        tracker.get());
    runs.push_back(RunOne("still", &rig, tracker.get(),
                          static_cast<int>(std::lround(options.still_seconds * options.fps)),
                          options.still_seconds / 2));
  }
  if (options.drive_seconds > 0.0) {
    sim.path = SimPath::kLoop;
    loop.target = options.drive_target;
    SimHeadStart start;
    start.offset_from_target = Eigen::Vector2d::Zero();
    const auto tracker = MakeTracker();
    SimulatedLiveRig rig(
        model, &area, camera,
        SimulatedLiveRigOptions{sim, SimulatedHeadOptions{}, loop, start, options.jitter},
        tracker.get());
    runs.push_back(RunOne("drive", &rig, tracker.get(),
                          static_cast<int>(std::lround(options.drive_seconds * options.fps)),
                          options.settle_seconds));
  }
  return runs;
}

}  // namespace linetrack::app

#include "tracking/sim/sim_rig.h"

#include "models/errors.h"
#include "tracking/head/head_pointing.h"

namespace linetrack {

LiveLoopOptions NominalBelief(const SimCameraOptions& camera, LiveLoopOptions loop) {
  loop.servo.geometry = GeometryOf(camera.head_model);
  loop.crossing_height = CrossingHeightFor(loop.servo.geometry, camera.camera_height);
  return loop;
}

SimulatedLiveRig::SimulatedLiveRig(const WireframeModel& model, const NavigableArea* area,
                                   const CameraIntrinsics& camera,
                                   const SimulatedLiveRigOptions& rig_options,
                                   CameraPoseEstimator* estimator)
    : undistorted_(camera.Undistorted()), camera_(model, area, camera, rig_options.camera) {
  const SimHeadStart& start = rig_options.start;
  const LiveLoopOptions& loop_options = rig_options.loop;
  SimulatedHeadOptions head = rig_options.head;
  if (start.offset_from_target) {
    if (!loop_options.target) {
      throw InputError("simulated head: a start relative to the target needs a target");
    }
    double pan = 0.0, tilt = 0.0;
    if (!HeadAnglesLookingAt(
            camera_.geometry(),
            WorldFromHeadBase(camera_.geometry(), camera_.BaseAt(0.0), camera_.crossing_height()),
            *loop_options.target, &pan, &tilt)) {
      throw InputError("simulated head: the target is too close to the head to look at");
    }
    head.initial_pan = pan + start.offset_from_target->x();
    head.initial_tilt = tilt + start.offset_from_target->y();
  }
  head_ = std::make_unique<SimulatedHead>(head);
  camera_.AttachHead(head_.get());
  truth_ = std::make_unique<SimulatorTruthEstimator>(&camera_, rig_options.jitter);
  estimator_ = estimator != nullptr ? estimator : truth_.get();
  loop_ =
      std::make_unique<LiveLoop>(LiveLoopParts{&camera_, head_.get(), estimator_,
                                               [this](double t) { return camera_.OdometryAt(t); }},
                                 model, undistorted_, loop_options);
}

double SimulatedLiveRig::TrueErrorPx() const {
  if (!loop_->target()) return -1.0;
  const Eigen::Vector3d seen = camera_.last_cam_from_world() * *loop_->target();
  return (undistorted_.Project(seen) - loop_->desired_px()).norm();
}

}  // namespace linetrack

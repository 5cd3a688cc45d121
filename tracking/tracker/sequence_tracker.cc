#include "tracking/tracker/sequence_tracker.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "models/errors.h"
#include "models/statistics.h"

namespace linetrack {

namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::optional<KnownHeightTilt> Known(const std::optional<RobotReading>& robot) {
  if (!robot) return std::nullopt;
  return KnownHeightTilt{robot->height, robot->tilt};
}

RobotPose WithReading(const Pose3Dof& planar, const RobotReading& robot) {
  return RobotPose{planar.x, planar.y, planar.heading, robot.height, robot.tilt};
}

}  // namespace

const char* ToString(TrackStatus status) {
  switch (status) {
    case TrackStatus::kInitialising:
      return "initialising";
    case TrackStatus::kTracking:
      return "tracking";
    case TrackStatus::kLost:
      return "lost";
    case TrackStatus::kRelocalised:
      return "relocalised";
  }
  return "unknown";
}

Eigen::Isometry3d PredictFromOdometry(const Eigen::Isometry3d& last, const RobotPose& then,
                                      const RobotPose& now) {
  return CamFromWorld(now) * CamFromWorld(then).inverse() * last;
}

bool SequenceTrackerOptions::Check(std::string* why) const {
  RobotConstraint tolerances = robot_tolerances;
  tolerances.height = 0.0;
  tolerances.tilt = 0.0;
  if (!health.Check(why) || !motion.Check(why) || !tolerances.Check(why)) return false;
  if (restart_window < 0) {
    *why = "restart window must be >= 0 frames";
    return false;
  }
  if (!(jump_ratio > 1.0) || !(jump_floor_deg >= 0.0) || jump_window < 1) {
    *why = "projection error jump: ratio > 1, floor >= 0, window >= 1";
    return false;
  }
  if (!(rms_jump_ratio > 1.0) || !(rms_jump_floor_px >= 0.0)) {
    *why = "refinement residual jump: ratio > 1, floor >= 0";
    return false;
  }
  if (!(prediction_min_px >= 0.0)) {
    *why = "prediction threshold must be >= 0 px";
    return false;
  }
  return true;
}

SequenceTracker::SequenceTracker(EdgeTracker* tracker, const CameraIntrinsics& camera,
                                 const Relocalizer* relocalizer,
                                 const SequenceTrackerOptions& options)
    : tracker_(tracker),
      undistorter_(camera),
      relocalizer_(relocalizer),
      options_(options),
      undistorted_(&empty_) {
  std::string why;
  if (!options_.Check(&why)) throw InputError("tracking options: " + why);
}

std::string SequenceTracker::Judge(const EdgeTrackResult& result, double t,
                                   const std::optional<RobotReading>& robot) const {
  if (!result.ok) return result.reason;
  std::string problem = HealthProblem(result.health, options_.health);
  if (problem.empty() && robot && options_.robot_requires_refinement &&
      tracker_->settings().refine_subpixel && !result.health.refined) {
    problem = "the image edges do not confirm the pose (sub-pixel refinement: " +
              std::to_string(result.health.refined_points) + " points)";
  }
  if (problem.empty() && robot) {
    RobotConstraint constraint = options_.robot_tolerances;
    constraint.height = robot->height;
    constraint.tilt = robot->tilt;
    // ViSP's own pose (6 unknowns) drifting from the robot's height and tilt betrays a bad track.
    problem = ConstraintProblem(result.visp_cam_from_world, constraint);
  }
  if (problem.empty() &&
      recent_projection_errors_.size() * 3 >= static_cast<size_t>(options_.jump_window)) {
    const double median = QuantileNearestRank(recent_projection_errors_, 0.5);
    const double limit = std::max(options_.jump_ratio * median, options_.jump_floor_deg);
    if (result.health.projection_error_deg > limit) {
      char text[128];
      std::snprintf(text, sizeof(text), "projection error jumped to %.1f deg (recent median %.1f)",
                    result.health.projection_error_deg, median);
      problem = text;
    }
  }
  if (problem.empty() && robot && result.health.refined &&
      recent_refined_rms_.size() * 3 >= static_cast<size_t>(options_.jump_window)) {
    const double median = QuantileNearestRank(recent_refined_rms_, 0.5);
    const double limit = std::max(options_.rms_jump_ratio * median, options_.rms_jump_floor_px);
    if (result.health.refined_rms_after_px > limit) {
      char text[128];
      std::snprintf(text, sizeof(text),
                    "the image edges fit worse: refinement residual %.2f px (recent median %.2f)",
                    result.health.refined_rms_after_px, median);
      problem = text;
    }
  }
  if (problem.empty() && last_good_) {
    problem = MotionProblem(last_good_->cam_from_world, result.cam_from_world, t - last_good_->t,
                            options_.motion);
  }
  return problem;
}

void SequenceTracker::Accept(const EdgeTrackResult& result, double t,
                             const std::optional<RobotReading>& robot, const char* source,
                             FrameReport* report) {
  following_ = true;
  last_good_ = GoodPose{result.cam_from_world, t, robot};
  recent_projection_errors_.push_back(result.health.projection_error_deg);
  while (recent_projection_errors_.size() > static_cast<size_t>(options_.jump_window))
    recent_projection_errors_.pop_front();
  if (result.health.refined) recent_refined_rms_.push_back(result.health.refined_rms_after_px);
  while (recent_refined_rms_.size() > static_cast<size_t>(options_.jump_window))
    recent_refined_rms_.pop_front();
  last_good_index_ = frame_index_;
  report->cam_from_world = result.cam_from_world;
  report->source = source;
  report->note.clear();
}

bool SequenceTracker::StartAndVerify(const Eigen::Isometry3d& candidate, double t,
                                     const std::optional<RobotReading>& robot,
                                     FrameReport* report) {
  following_ = false;
  const EdgeTrackResult started = tracker_->Start(*undistorted_, candidate);
  if (!started.ok) {
    report->note = started.reason;
    return false;
  }
  const EdgeTrackResult result =
      tracker_->Track(*undistorted_, /*with_covariance=*/true, Known(robot));
  report->health = result.health;
  report->health_measured = result.ok;
  const std::string problem = Judge(result, t, robot);
  if (!problem.empty()) {
    report->note = problem;
    return false;
  }
  following_ = true;
  report->cam_from_world = result.cam_from_world;
  return true;
}

bool SequenceTracker::MatcherPrior(const RobotReading& robot, RobotPose* prior,
                                   SearchBounds* bounds) const {
  const RelocalizationOptions& options = relocalizer_->options();
  if (robot.odometry && last_good_ && last_good_->robot && last_good_->robot->odometry) {
    const RobotPose good = RobotPoseFromCamFromWorld(last_good_->cam_from_world);
    *prior = CarryPrior(good, WithReading(*last_good_->robot->odometry, *last_good_->robot),
                        WithReading(*robot.odometry, robot));
    *bounds = WidenedBounds(FramesSinceGood(), options);
  } else if (robot.odometry) {
    *prior = WithReading(*robot.odometry, robot);
    *bounds = options.initial;
  } else if (last_good_) {
    *prior = WithReading(RobotPoseFromCamFromWorld(last_good_->cam_from_world).Planar(), robot);
    *bounds = WidenedBounds(FramesSinceGood(), options);
  } else if (initial_prior_) {
    *prior = WithReading(*initial_prior_, robot);
    *bounds = options.initial;
  } else {
    return false;
  }
  return true;
}

void SequenceTracker::MaybePredict(const std::optional<RobotReading>& robot, FrameReport* report) {
  if (!robot || !robot->odometry || !last_good_ || !last_good_->robot ||
      !last_good_->robot->odometry) {
    return;
  }
  const RobotReading& then = *last_good_->robot;
  const Eigen::Isometry3d predicted =
      PredictFromOdometry(last_good_->cam_from_world, WithReading(*then.odometry, then),
                          WithReading(*robot->odometry, *robot));
  // The model's own image motion: driving forward or at a distance moves the image little.
  if (tracker_->ImageMotionPx(last_good_->cam_from_world, predicted) <=
      options_.prediction_min_px) {
    return;
  }
  // Aligned on the edges when they are found, else started from the prediction as it is.
  if (!tracker_->StartFromPrediction(*undistorted_, predicted, Known(robot)).ok) {
    tracker_->Start(*undistorted_, predicted);
  }
  report->predicted = true;
}

FrameReport SequenceTracker::Process(const vpImage<unsigned char>& image, double t,
                                     const std::optional<RobotReading>& robot) {
  const Clock::time_point start = Clock::now();
  ++frame_index_;
  FrameReport report;
  undistorted_ = &undistorter_.Apply(image);
  report.undistort_ms = MillisecondsSince(start);

  if (following_) {
    const Clock::time_point track_start = Clock::now();
    MaybePredict(robot, &report);
    report.predict_ms = MillisecondsSince(track_start);
    const EdgeTrackResult result = tracker_->Track(*undistorted_, false, Known(robot));
    report.track_ms = MillisecondsSince(track_start);
    report.passes_ms = result.passes_ms;
    report.measure_ms = result.measure_ms;
    report.health = result.health;
    report.health_measured = result.ok;
    const std::string problem = Judge(result, t, robot);
    if (problem.empty()) {
      Accept(result, t, robot, "tracker", &report);
      report.status = TrackStatus::kTracking;
    } else {
      following_ = false;
      ++losses_;
      report.status = TrackStatus::kLost;
      report.note = problem;
    }
    report.total_ms = MillisecondsSince(start);
    return report;
  }

  // Not following: find the pose (again). Candidates in order; each is verified by tracking.
  const Clock::time_point search_start = Clock::now();
  const bool had_pose = last_good_.has_value();
  const char* source = nullptr;
  auto try_candidate = [&](const Eigen::Isometry3d& candidate, const char* name) {
    if (!StartAndVerify(candidate, t, robot, &report)) return false;
    source = name;
    return true;
  };
  if (start_pose_ && try_candidate(*start_pose_, "start pose")) start_pose_.reset();
  if (!source && relocalizer_ && robot) {
    RobotPose prior;
    SearchBounds bounds;
    if (MatcherPrior(*robot, &prior, &bounds)) {
      const RelocalizationAttempt attempt = relocalizer_->Attempt(*undistorted_, prior, bounds);
      report.lines = attempt.lines;
      if (!attempt.found) {
        report.note = attempt.reason;
      } else {
        try_candidate(attempt.cam_from_world, "matcher");
      }
    } else {
      report.note = "no prior for the matcher";
    }
  }
  if (!source && options_.restart_from_last_good && last_good_ &&
      FramesSinceGood() <= options_.restart_window) {
    const std::string matcher_note = report.note;
    if (!try_candidate(last_good_->cam_from_world, "restart") && !matcher_note.empty()) {
      report.note = matcher_note + "; restart: " + report.note;
    }
  }
  if (!source && !start_pose_ && !(relocalizer_ && robot) && !last_good_) {
    report.note = "no start pose and no prior";
  }
  report.relocalize_ms = MillisecondsSince(search_start);
  if (source) {
    const Eigen::Isometry3d pose = *report.cam_from_world;
    EdgeTrackResult accepted;
    accepted.ok = true;
    accepted.cam_from_world = pose;
    accepted.health = report.health;
    Accept(accepted, t, robot, source, &report);
    report.status = had_pose ? TrackStatus::kRelocalised : TrackStatus::kTracking;
    if (had_pose) ++recoveries_;
  } else {
    report.status = had_pose ? TrackStatus::kLost : TrackStatus::kInitialising;
    report.cam_from_world.reset();
  }
  report.total_ms = MillisecondsSince(start);
  return report;
}

}  // namespace linetrack

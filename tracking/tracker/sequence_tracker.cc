#include "tracking/tracker/sequence_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "models/errors.h"
#include "models/statistics.h"
#include "models/text_format.h"
#include "tracking/tracker/planar_readings.h"

namespace linetrack {

namespace {

using Clock = std::chrono::steady_clock;

std::optional<KnownHeightTilt> Known(const std::optional<RobotReading>& robot) {
  if (!robot) return std::nullopt;
  return KnownHeightTilt{robot->height, robot->tilt, robot->roll};
}

// Where the odometry carries `pose` from the reading `then` to `now` (both with odometry).
Pose3Dof Carry(const Pose3Dof& pose, const RobotReading& then, const RobotReading& now) {
  return CarryPrior(WithReading(pose, now), WithReading(*then.odometry, then),
                    WithReading(*now.odometry, now))
      .Planar();
}

}  // namespace

bool ReacquisitionCheck::Check(std::string* why) const {
  if (confirm_frames < 0 || !(allowance_m >= 0.0) || !(drift_share >= 0.0) ||
      !(heading_allowance_rad >= 0.0) || !(confirm_distance_m >= 0.0)) {
    *why = "reacquisition: frames, allowances, drift share and distance must be >= 0";
    return false;
  }
  return true;
}

double ReacquisitionAllowanceM(const ReacquisitionCheck& check, double driven_m) {
  return check.allowance_m + check.drift_share * driven_m;
}

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
    case TrackStatus::kCoasting:
      return "coasting";
  }
  return "unknown";
}

bool SequenceTrackerOptions::Check(std::string* why) const {
  RobotConstraint tolerances = robot_tolerances;
  tolerances.height = 0.0;
  tolerances.tilt = 0.0;
  tolerances.roll = 0.0;
  if (!health.Check(why) || !motion.Check(why) || !tolerances.Check(why)) return false;
  if (!integrity.Check(why) || !reacquisition.Check(why) || !coast.Check(why)) return false;
  if (!global.Check(why)) return false;
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
              std::to_string(result.health.refined_points) + " points, " +
              result.health.refinement_refusal + ")";
  }
  if (problem.empty() && robot) {
    RobotConstraint constraint = options_.robot_tolerances;
    constraint.height = robot->height;
    constraint.tilt = robot->tilt;
    constraint.roll = robot->roll;
    // ViSP's own pose (6 unknowns) drifting from the robot's height, tilt and roll betrays a bad
    // track.
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
  ever_good_ = true;
  carry_frames_ = 0;
  carry_seen_.reset();
  last_good_ = GoodPose{result.cam_from_world, t, robot, driven_m_};
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
  verified_observations_ = result.observations;
  return true;
}

void SequenceTracker::Assess(const std::vector<EdgeObservation>& observations,
                             const std::optional<RobotReading>& robot, FrameReport* report) {
  PoseUncertainty& u = report->uncertainty;
  if (observations.empty()) {
    u = PoseUncertainty();
    u.status = IntegrityStatus::kDegraded;
    u.reason = "no edge points bound the pose (sub-pixel refinement not applied)";
    return;
  }
  // The tracker's pose is reported (it is the one the next frame starts from); the levels bound
  // its error.
  IntegrityOptions options = options_.integrity;
  options.bound_start_pose = true;
  const PoseIntegrity integrity =
      EvaluatePoseIntegrity(observations, tracker_->camera(), *report->cam_from_world,
                            PoseParameterisation(Known(robot)), options);
  u = UncertaintyOf(integrity);
  if (integrity.status == IntegrityStatus::kLost) report->cam_from_world.reset();
}

bool SequenceTracker::CheckReacquisition(const std::optional<RobotReading>& robot,
                                         const std::optional<GoodPose>* started_after,
                                         FrameReport* report) {
  if (!report->cam_from_world) return true;  // lost to the integrity monitor: nothing to check
  const ReacquisitionCheck& check = options_.reacquisition;
  PoseUncertainty& u = report->uncertainty;
  const Pose3Dof pose = PlanarOf(*report->cam_from_world);
  const bool odometry = robot && robot->odometry;
  const double sigma = u.has_covariance() ? 3.0 * std::max(u.sigma_x_m, u.sigma_y_m) : 0.0;
  if (started_after || !reacquisition_) {
    reacquisition_ = NewReacquisition(pose, robot, started_after, sigma);
  } else {
    Reacquisition& r = *reacquisition_;
    ++r.frames;
    if (odometry && r.robot && r.robot->odometry) {
      const Eigen::Vector2d d = PlanarDifference(pose, Carry(r.pose, *r.robot, *robot));
      const double driven = driven_m_ - r.driven_at_start_m;
      const double allowance = ReacquisitionAllowanceM(check, driven) + sigma;
      if (d[0] > allowance || d[1] > check.heading_allowance_rad + check.drift_share * driven) {
        report->note = "the re-localised pose moved " + Fixed(d[0], 2) + " m / " +
                       Fixed(RadToDeg(d[1]), 1) + " deg away from the odometry's motion";
        return false;
      }
    }
  }
  const Reacquisition& r = *reacquisition_;
  const double driven = driven_m_ - r.episode_start_m;
  if (r.frames >= check.confirm_frames && driven >= r.needed_m) {
    reacquisition_.reset();
    global_reason_.clear();  // a confirmed pose: the global mode's drop is over
    global_before_.reset();
    return true;
  }
  std::string why = "re-localisation being confirmed: " + std::to_string(r.frames) + " of " +
                    std::to_string(check.confirm_frames) + " frames";
  if (!r.jump.empty()) {
    why += ", " + Fixed(driven, 1) + " of " + Fixed(r.needed_m, 1) + " m; " + r.jump;
    // Either the re-localised pose or the one the odometry carries may be right: the covariance
    // and the protection levels span both.
    if (u.has_covariance()) {
      u.world_covariance(0, 0) += r.jump_m * r.jump_m;
      u.world_covariance(1, 1) += r.jump_m * r.jump_m;
      u.world_covariance(5, 5) += r.jump_rad * r.jump_rad;
      u.sigma_x_m = std::sqrt(u.world_covariance(0, 0));
      u.sigma_y_m = std::sqrt(u.world_covariance(1, 1));
      u.sigma_heading_rad = std::sqrt(u.world_covariance(5, 5));
      u.protection_position_m += r.jump_m;
      u.protection_rotation_rad += r.jump_rad;
    }
  }
  if (u.status == IntegrityStatus::kTracking) u.status = IntegrityStatus::kDegraded;
  u.reason = u.reason.empty() ? why : why + "; " + u.reason;
  return true;
}

SequenceTracker::Reacquisition SequenceTracker::NewReacquisition(
    const Pose3Dof& pose, const std::optional<RobotReading>& robot,
    const std::optional<GoodPose>* started_after, double sigma) const {
  const ReacquisitionCheck& check = options_.reacquisition;
  Reacquisition r;
  r.pose = pose;
  r.robot = robot;
  r.driven_at_start_m = r.episode_start_m = driven_m_;
  if (started_after) r.before = *started_after;
  r.global = global_mode_;
  if (r.global) r.before.reset();
  // A re-localisation while a global one is unconfirmed (the tracker lost it, the matcher found
  // it again around it) continues that one: nothing else before it bounds it either.
  if (reacquisition_ && reacquisition_->global) {
    r.global = true;
    r.before.reset();
    r.reference = reacquisition_->reference;
    r.episode_start_m = reacquisition_->episode_start_m;
  } else {
    r.reference = r.global ? global_before_ : r.before;
  }
  const GoodPose* reference = r.reference ? &*r.reference : nullptr;
  if (reference && robot && robot->odometry && reference->robot && reference->robot->odometry) {
    const Eigen::Vector2d d = PlanarDifference(
        pose, Carry(PlanarOf(reference->cam_from_world), *reference->robot, *robot));
    const double driven = driven_m_ - reference->driven_m;
    const double allowance = ReacquisitionAllowanceM(check, driven) + sigma;
    if (d[0] > allowance || d[1] > check.heading_allowance_rad + check.drift_share * driven) {
      r.jump_m = d[0];
      r.jump_rad = d[1];
      r.jump = Fixed(d[0], 2) + " m / " + Fixed(RadToDeg(d[1]), 1) +
               " deg from where the odometry carries " +
               (r.global ? "the pose the global mode left" : "the last good pose") +
               " (allowance " + Fixed(allowance, 2) + " m)";
      r.needed_m = check.confirm_distance_m;
    }
  }
  return r;
}

void SequenceTracker::Drop(const std::string& why, FrameReport* report) {
  following_ = false;
  ++losses_;
  if (reacquisition_ && reacquisition_->before) {
    last_good_ = reacquisition_->before;
    last_good_index_ = frame_index_;
  }
  // A global pose that fails its confirmation leaves nothing to search around: global again.
  if (reacquisition_ && reacquisition_->global) {
    global_mode_ = true;
    last_good_.reset();
  }
  reacquisition_.reset();
  report->status = TrackStatus::kLost;
  report->note = why;
  report->cam_from_world.reset();
  report->uncertainty = PoseUncertainty();
  report->uncertainty.reason = why;
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

void SequenceTracker::Follow(double t, const std::optional<RobotReading>& robot,
                             FrameReport* report) {
  const Clock::time_point track_start = Clock::now();
  MaybePredict(robot, report);
  report->predict_ms = MillisecondsSince(track_start);
  const EdgeTrackResult result =
      tracker_->Track(*undistorted_, /*with_covariance=*/false, Known(robot));
  report->track_ms = MillisecondsSince(track_start);
  report->passes_ms = result.passes_ms;
  report->measure_ms = result.measure_ms;
  report->health = result.health;
  report->health_measured = result.ok;
  const std::string problem = Judge(result, t, robot);
  if (!problem.empty()) {
    following_ = false;
    ++losses_;
    report->status = TrackStatus::kLost;
    report->note = problem;
    report->uncertainty.reason = problem;
    return;
  }
  Accept(result, t, robot, "tracker", report);
  report->status = TrackStatus::kTracking;
  Assess(result.observations, robot, report);
  if (robot) RetestHypothesis(*robot);
  if (reacquisition_ && !CheckReacquisition(robot, nullptr, report)) Drop(report->note, report);
}

const char* SequenceTracker::Search(double t, const std::optional<RobotReading>& robot,
                                    const std::optional<CoastedPose>& coasted,
                                    FrameReport* report) {
  if (start_pose_ && StartAndVerify(*start_pose_, t, robot, report)) {
    start_pose_.reset();
    global_mode_ = false;
    global_before_.reset();
    return "start pose";
  }
  if (global_ && robot) {
    MaybeSwitchToGlobal(*robot);
    if (global_mode_) return TryGlobal(t, *robot, report) ? "global" : nullptr;
  }
  if (relocalizer_ && robot) {
    RobotPose prior;
    SearchBounds bounds;
    if (MatcherPrior(*robot, &prior, &bounds)) {
      const RelocalizationAttempt attempt = relocalizer_->Attempt(*undistorted_, prior, bounds);
      report->lines = attempt.lines;
      // The frame may disagree with the prior only when the matcher finds nothing around it; a
      // pose found there that the edges do not hold says the prior still fits.
      if (attempt.found) {
        // Reset once the pose is checked for a rival (HasRival counts the frames before it).
      } else if (attempt.lines >= options_.global.kidnap_min_lines) {
        ProbeCarry(*robot, prior.Planar());
        if (global_) MaybeSwitchToGlobal(*robot);
        if (global_mode_) return TryGlobal(t, *robot, report) ? "global" : nullptr;
      }
      image_allows_coasting_ = attempt.found || attempt.lines < options_.global.kidnap_min_lines;
      if (!attempt.found) {
        report->note = attempt.reason;
      } else if (StartAndVerify(attempt.cam_from_world, t, robot, report)) {
        const bool rival = HasRival(attempt.cam_from_world, *robot, report);
        carry_frames_ = 0;
        carry_seen_.reset();
        return rival ? nullptr : "matcher";
      }
      if (attempt.found) {
        carry_frames_ = 0;
        carry_seen_.reset();
      }
    } else {
      report->note = "no prior for the matcher";
    }
  }
  if (global_mode_) return nullptr;  // the matcher's pose had a rival
  // A restart from where the odometry carries the last reported pose, else from the last good
  // pose; the carried one is checked for a rival as the matcher's is (a robot carried to a place
  // that looks the same holds the carried pose on the image).
  const bool coasting = coasted && coasted->uncertainty.status != IntegrityStatus::kLost;
  std::optional<Eigen::Isometry3d> restart;
  if (coasting) {
    restart = coasted->cam_from_world;
  } else if (last_good_ && FramesSinceGood() <= options_.restart_window) {
    restart = last_good_->cam_from_world;
  }
  if (options_.restart_from_last_good && restart) {
    const std::string matcher_note = report->note;
    if (StartAndVerify(*restart, t, robot, report)) {
      return coasting && robot && HasRival(*report->cam_from_world, *robot, report) ? nullptr
                                                                                    : "restart";
    }
    if (!matcher_note.empty()) report->note = matcher_note + "; restart: " + report->note;
  }
  if (!start_pose_ && !(relocalizer_ && robot) && !last_good_) {
    report->note = "no start pose and no prior";
  }
  return nullptr;
}

FrameReport SequenceTracker::Process(const vpImage<unsigned char>& image, double t,
                                     const std::optional<RobotReading>& robot) {
  const Clock::time_point start = Clock::now();
  ++frame_index_;
  if (frame_index_ > 0 && t > t_) {
    recent_intervals_.push_back(t - t_);
    if (recent_intervals_.size() > 15) recent_intervals_.pop_front();
  }
  t_ = t;
  if (robot && robot->odometry) {
    if (last_odometry_) {
      driven_m_ += std::hypot(robot->odometry->x - last_odometry_->x,
                              robot->odometry->y - last_odometry_->y);
    }
    last_odometry_ = robot->odometry;
  }
  FrameReport report;
  image_allows_coasting_ = false;
  image_refutes_coasting_ = false;
  probe_.reset();
  undistorted_ = &undistorter_.Apply(image);
  report.undistort_ms = MillisecondsSince(start);

  const std::optional<CoastedPose> coasted = CoastToFrame(robot);
  if (following_) {
    Follow(t, robot, &report);
    if (report.status == TrackStatus::kLost && coasted && robot) CheckCoasted(*robot, *coasted);
    WithholdUnconfirmedGlobal(&report);
    Combine(robot, coasted, &report);
    report.total_ms = MillisecondsSince(start);
    return report;
  }

  // Not following: find the pose (again). Candidates in order; each is verified by tracking.
  const Clock::time_point search_start = Clock::now();
  const bool had_pose = ever_good_;
  const char* source = Search(t, robot, coasted, &report);
  report.relocalize_ms = MillisecondsSince(search_start);
  if (source) {
    const Eigen::Isometry3d pose = *report.cam_from_world;
    EdgeTrackResult accepted;
    accepted.ok = true;
    accepted.cam_from_world = pose;
    accepted.health = report.health;
    std::optional<GoodPose> before = last_good_;
    if (reacquisition_ && reacquisition_->before) before = reacquisition_->before;
    Accept(accepted, t, robot, source, &report);
    report.status = had_pose ? TrackStatus::kRelocalised : TrackStatus::kTracking;
    if (had_pose) ++recoveries_;
    Assess(verified_observations_, robot, &report);
    // A global pose has no pose before it: its check starts afresh, against nothing; unless it
    // (or a pose found with no good pose before it) agrees with the pose the global mode left,
    // carried by the odometry, which then bounds it as a last good pose bounds a re-localisation.
    const bool global = std::string(source) == "global";
    if ((global || !before) && robot && report.cam_from_world &&
        AgreesWithGlobalBefore(pose, *robot)) {
      before = global_before_;
      global_mode_ = false;
    } else if (global) {
      before.reset();
    }
    const bool matcher = global || std::string(source) == "matcher";
    if (global && !report.cam_from_world) {
      // The integrity monitor finds the global pose lost: nothing to confirm, search again.
      following_ = false;
      last_good_.reset();
    } else if ((matcher || reacquisition_) &&
               !CheckReacquisition(robot, matcher ? &before : nullptr, &report)) {
      Drop(report.note, &report);
    }
    if (global && report.cam_from_world) {
      report.uncertainty.reason =
          "global mode (" + global_reason_ + "); " + report.uncertainty.reason;
      global_mode_ = false;
    }
  } else {
    report.status = had_pose ? TrackStatus::kLost : TrackStatus::kInitialising;
    report.cam_from_world.reset();
    report.uncertainty.reason = report.note;
  }
  WithholdUnconfirmedGlobal(&report);
  Combine(robot, coasted, &report);
  report.total_ms = MillisecondsSince(start);
  return report;
}

}  // namespace linetrack

// The tracking engine's recovery paths (sequence_tracker.h): the global mode of a lost or
// carried robot, and coasting on the odometry through frames without an image pose.
#include <algorithm>
#include <string>

#include "models/statistics.h"
#include "models/text_format.h"
#include "tracking/tracker/planar_readings.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {
namespace {

// The matcher's bounds around the pose the global mode left, carried `driven_m` metres by the
// odometry: the reacquisition allowance, at least the bounds just after a loss.
SearchBounds HypothesisBounds(const RelocalizationOptions& relocalization,
                              const ReacquisitionCheck& check, double driven_m) {
  const SearchBounds& after_loss = relocalization.after_loss;
  return {
      std::max(after_loss.delta_t, ReacquisitionAllowanceM(check, driven_m)),
      std::max(after_loss.delta_phi, check.heading_allowance_rad + check.drift_share * driven_m)};
}

}  // namespace

void SequenceTracker::EnterGlobalMode(const std::string& why) {
  following_ = false;
  // An unconfirmed global pose is no hypothesis: the one its confirmation is held against stays.
  if (last_good_ && !(reacquisition_ && reacquisition_->global)) {
    global_before_ = last_good_;
    global_before_confirmed_ = !reacquisition_;
  }
  last_good_.reset();
  reacquisition_.reset();
  recent_projection_errors_.clear();
  recent_refined_rms_.clear();
  global_mode_ = true;
  global_reason_ = why;
  carry_frames_ = 0;
  carry_seen_.reset();
  hypothesis_refutations_ = 0;
  anchor_.reset();  // the odometry carries the old pose, not the robot
}

void SequenceTracker::RequestGlobal() {
  start_pose_.reset();
  initial_prior_.reset();
  EnterGlobalMode("asked");
  global_before_.reset();  // every prior is dropped
}

bool SequenceTracker::HasRival(const Eigen::Isometry3d& pose, const RobotReading& robot,
                               FrameReport* report) {
  const GlobalRecoveryOptions& o = options_.global;
  if (!global_ || !o.check_relocalisations || !ever_good_) return false;
  const GlobalAttempt g = global_->Attempt(*undistorted_, robot.height, robot.tilt);
  std::string rival;
  if (carry_frames_ > 0) {
    // A frame since the last good pose showed the robot elsewhere: the view near the prior may
    // be the twin of where the robot was carried (the office's corridors).
    rival = std::to_string(carry_frames_) + " frames before showed the robot elsewhere";
  } else if (g.ambiguous) {
    rival = "the global mode finds the view ambiguous (" + std::to_string(g.rivals) + " rivals)";
  } else if (g.found) {
    const Eigen::Vector2d d = PlanarDifference(PlanarOf(g.cam_from_world), PlanarOf(pose));
    if (d[0] > o.rival_distance_m || d[1] > DegToRad(o.rival_heading_deg)) {
      rival = "the global mode finds a pose " + Fixed(d[0], 2) + " m / " +
              Fixed(RadToDeg(d[1]), 1) + " deg away";
    }
  }
  if (rival.empty()) return false;
  // The matcher's pose, verified on this frame, is a hypothesis the global mode must refute
  // (unless it was found around an unconfirmed global pose: that one's reference stays).
  const GoodPose matcher{pose, t_, robot, driven_m_};
  const bool keep = reacquisition_ && reacquisition_->global;
  EnterGlobalMode("the matcher's pose near the prior has a rival: " + rival);
  report->cam_from_world.reset();
  report->source = "global";
  report->note = "global mode (" + global_reason_ + ")";
  if (!keep) {
    global_before_ = matcher;
    global_before_confirmed_ = false;
  }
  return true;
}

void SequenceTracker::MaybeSwitchToGlobal(const RobotReading& robot) {
  if (global_mode_) return;
  LossState state;
  RobotPose prior;
  SearchBounds bounds;
  state.has_prior = relocalizer_ && MatcherPrior(robot, &prior, &bounds);
  state.frames_since_good = last_good_ ? FramesSinceGood() : static_cast<int>(frame_index_ + 1);
  state.carry_frames = carry_frames_;
  state.frame_period_s = FramePeriod();
  if (robot.odometry) state.driven_since_m = driven_m_ - (last_good_ ? last_good_->driven_m : 0.0);
  const std::string why = GlobalModeReason(state, options_.global);
  if (why.empty()) return;
  const int refutations = carry_frames_;
  // The old pose and its statistics say nothing of where the robot is now.
  EnterGlobalMode(why);
  // The frames that showed the robot elsewhere refuted the pose the global mode left, carried.
  for (int i = 0; i < refutations && global_before_; ++i)
    RefuteHypothesis();
}

int SequenceTracker::RefutationsNeeded() const {
  return std::max(options_.global.kidnap_min_frames, CarryFrames(options_.global, FramePeriod()));
}

bool SequenceTracker::RefuteHypothesis() {
  if (!global_before_) return true;
  if (++hypothesis_refutations_ < RefutationsNeeded()) return false;
  global_before_.reset();
  global_reason_ += "; a carry: " + std::to_string(hypothesis_refutations_) +
                    " frames refute the pose the mode left";
  return true;
}

void SequenceTracker::ProbeCarry(const RobotReading& robot, const Pose3Dof& prior) {
  if (!global_ || !ever_good_ || global_mode_ || CarryFrames(options_.global, FramePeriod()) == 0)
    return;
  probe_ = global_->Attempt(*undistorted_, robot.height, robot.tilt);
  if (!ShowsElsewhere(*probe_, prior, options_.global)) {
    // A pose near the prior is no carry; a frame the global mode cannot place says nothing.
    if (probe_->found) {
      carry_frames_ = 0;
      carry_seen_.reset();
    }
    return;
  }
  image_refutes_coasting_ = true;
  if (probe_->found) {
    // Frames that show the robot elsewhere must agree on where (the odometry carrying the last).
    if (carry_seen_ && carry_seen_->robot && carry_seen_->robot->odometry && robot.odometry) {
      const RobotReading& then = *carry_seen_->robot;
      const Eigen::Isometry3d carried =
          PredictFromOdometry(carry_seen_->cam_from_world, WithReading(*then.odometry, then),
                              WithReading(*robot.odometry, robot));
      const Eigen::Vector2d d = PlanarDifference(probe_->planar, PlanarOf(carried));
      if (d[0] > options_.global.rival_distance_m ||
          d[1] > DegToRad(options_.global.rival_heading_deg)) {
        carry_frames_ = 0;
      }
    }
    carry_seen_ = GoodPose{probe_->cam_from_world, t_, robot, driven_m_};
  }
  ++carry_frames_;
}

void SequenceTracker::CheckCoasted(const RobotReading& robot, const CoastedPose& coasted) {
  if (!relocalizer_ || coasted.uncertainty.status == IntegrityStatus::kLost) return;
  const Pose3Dof planar = PlanarOf(coasted.cam_from_world);
  const RelocalizationAttempt around = relocalizer_->Attempt(
      *undistorted_, WithReading(planar, robot), relocalizer_->options().after_loss);
  const int min_lines = options_.global.kidnap_min_lines;
  image_allows_coasting_ = around.found || around.lines < min_lines;
  if (around.found) {
    carry_frames_ = 0;
    carry_seen_.reset();
  } else if (around.lines >= min_lines) {
    ProbeCarry(robot, planar);
  }
}

void SequenceTracker::RetestHypothesis(const RobotReading& robot) {
  if (!reacquisition_ || !reacquisition_->global || reacquisition_->jump.empty() ||
      !global_before_ || !relocalizer_) {
    return;
  }
  const std::optional<Eigen::Isometry3d> before = CarriedGlobalBefore(robot);
  if (!before) return;
  const double driven = driven_m_ - global_before_->driven_m;
  const RelocalizationAttempt around = relocalizer_->Attempt(
      *undistorted_, WithReading(PlanarOf(*before), robot),
      HypothesisBounds(relocalizer_->options(), options_.reacquisition, driven));
  if (around.found) {
    hypothesis_refutations_ = 0;  // the frame holds it too: the view repeats
    return;
  }
  if (around.lines < options_.global.kidnap_min_lines || !RefuteHypothesis()) return;
  // Refuted over enough frames: the global pose is no longer held against it.
  Reacquisition& r = *reacquisition_;
  r.jump.clear();
  r.jump_m = 0.0;
  r.jump_rad = 0.0;
  r.needed_m = 0.0;
  r.reference.reset();
}

bool SequenceTracker::TryGlobal(double t, const RobotReading& robot, FrameReport* report) {
  report->source = "global";
  const GlobalAttempt attempt =
      probe_ ? *probe_ : global_->Attempt(*undistorted_, robot.height, robot.tilt);
  report->lines = attempt.lines;
  const std::string mode = "global mode (" + global_reason_ + "): ";
  const std::optional<Eigen::Isometry3d> before = CarriedGlobalBefore(robot);
  const double driven = before ? driven_m_ - global_before_->driven_m : 0.0;
  if (!attempt.found) {
    report->note = mode + attempt.reason;
    // With no rival on the frame (the global mode found no pose elsewhere, and the view is not
    // ambiguous), the search goes on around the pose the mode left as it would have without the
    // switch: a trigger with no carry (a blurred stretch) then costs no more frames.
    if (attempt.ambiguous || !before) return false;
    if (!SearchAroundHypothesis(*before, driven, t, robot, report)) {
      report->note = mode + attempt.reason + "; around the pose it left: " + report->note;
      return false;
    }
    return true;
  }
  if (!StartAndVerify(attempt.cam_from_world, t, robot, report)) {
    report->note = mode + "its pose is not confirmed by the edges: " + report->note;
    return false;
  }
  // Away from the pose the global mode left, the answer is either a carry or a view that repeats
  // elsewhere. Frames that hold the answer but not the pose left (carried by the odometry) show
  // a carry: that pose is dropped once refuted on RefutationsNeeded() frames, this one and the
  // confirmation's (RetestHypothesis). Until then both stay (NewReacquisition).
  if (!before) return true;
  const ReacquisitionCheck& check = options_.reacquisition;
  const Eigen::Vector2d d = PlanarDifference(PlanarOf(attempt.cam_from_world), PlanarOf(*before));
  if (d[0] <= ReacquisitionAllowanceM(check, driven) &&
      d[1] <= check.heading_allowance_rad + check.drift_share * driven) {
    return true;
  }
  if (HypothesisHolds(*before, driven, t, robot)) {
    hypothesis_refutations_ = 0;
  } else {
    RefuteHypothesis();
  }
  // The tracker back on the global pose (the same frame and start: the same result).
  if (!StartAndVerify(attempt.cam_from_world, t, robot, report)) {
    report->note = mode + "its pose is not confirmed by the edges: " + report->note;
    return false;
  }
  return true;
}

bool SequenceTracker::SearchAroundHypothesis(const Eigen::Isometry3d& hypothesis, double driven_m,
                                             double t, const RobotReading& robot,
                                             FrameReport* report) {
  if (relocalizer_) {
    const RelocalizationAttempt around = relocalizer_->Attempt(
        *undistorted_, WithReading(PlanarOf(hypothesis), robot),
        HypothesisBounds(relocalizer_->options(), options_.reacquisition, driven_m));
    if (around.found && StartAndVerify(around.cam_from_world, t, robot, report)) return true;
    report->note = around.found ? report->note : around.reason;
  }
  // A restart from the carried pose, within the restart window as after any loss.
  const double period = FramePeriod();
  if (!options_.restart_from_last_good || !(period > 0.0) ||
      t - global_before_->t > options_.restart_window * period) {
    return false;
  }
  const std::string matcher_note = report->note;
  if (StartAndVerify(hypothesis, t, robot, report)) return true;
  report->note = matcher_note + "; restart: " + report->note;
  return false;
}

bool SequenceTracker::AgreesWithGlobalBefore(const Eigen::Isometry3d& pose,
                                             const RobotReading& robot) const {
  const std::optional<Eigen::Isometry3d> before = CarriedGlobalBefore(robot);
  if (!before || !relocalizer_ || !global_before_confirmed_) return false;
  const SearchBounds bounds = HypothesisBounds(relocalizer_->options(), options_.reacquisition,
                                               driven_m_ - global_before_->driven_m);
  const Eigen::Vector2d d = PlanarDifference(PlanarOf(pose), PlanarOf(*before));
  return d[0] <= bounds.delta_t && d[1] <= bounds.delta_phi;
}

std::optional<Eigen::Isometry3d> SequenceTracker::CarriedGlobalBefore(
    const RobotReading& robot) const {
  if (!global_before_ || !global_before_->robot || !global_before_->robot->odometry ||
      !robot.odometry) {
    return std::nullopt;
  }
  const RobotReading& then = *global_before_->robot;
  return PredictFromOdometry(global_before_->cam_from_world, WithReading(*then.odometry, then),
                             WithReading(*robot.odometry, robot));
}

bool SequenceTracker::HypothesisHolds(const Eigen::Isometry3d& hypothesis, double driven_m,
                                      double t, const RobotReading& robot) {
  FrameReport scratch;
  if (StartAndVerify(hypothesis, t, robot, &scratch)) return true;
  if (!relocalizer_) return false;
  return relocalizer_
      ->Attempt(*undistorted_, WithReading(PlanarOf(hypothesis), robot),
                HypothesisBounds(relocalizer_->options(), options_.reacquisition, driven_m))
      .found;
}

double SequenceTracker::FramePeriod() const {
  if (recent_intervals_.empty()) return 0.0;
  return QuantileNearestRank(recent_intervals_, 0.5);
}

void SequenceTracker::WithholdUnconfirmedGlobal(FrameReport* report) const {
  // Also a matcher's pose after the global mode dropped the last good pose: nothing before it
  // bounds a wrong answer either (global_reason_ is kept until a pose is confirmed).
  // Past its confirm_frames a pose is reported: confirmed, or with the jump from the pose the
  // global mode left in its covariance (NewReacquisition).
  const bool unanchored = reacquisition_ && (reacquisition_->global ||
                                             (!global_reason_.empty() && !reacquisition_->before));
  if (!unanchored || !report->cam_from_world ||
      reacquisition_->frames >= options_.reacquisition.confirm_frames) {
    return;
  }
  report->cam_from_world.reset();
  PoseUncertainty& u = report->uncertainty;
  const std::string was = u.reason;
  u = PoseUncertainty();
  u.status = IntegrityStatus::kLost;
  u.reason = "a re-localisation with no good pose before it is reported once confirmed" +
             (was.empty() ? "" : ": " + was);
  report->note = u.reason;
}

std::optional<CoastedPose> SequenceTracker::CoastToFrame(
    const std::optional<RobotReading>& robot) const {
  if (!options_.coast.enabled || !anchor_ || !robot || !robot->odometry) return std::nullopt;
  return Coast(*anchor_, WithReading(*robot->odometry, *robot), options_.coast, options_.integrity);
}

void SequenceTracker::Combine(const std::optional<RobotReading>& robot,
                              const std::optional<CoastedPose>& coasted, FrameReport* report) {
  if (!options_.coast.enabled || !robot || !robot->odometry || global_mode_) {
    anchor_.reset();
    return;
  }
  const RobotPose now = WithReading(*robot->odometry, *robot);
  // The anchor is dropped during the frame when the global mode takes over (a carried robot).
  const bool coasting = anchor_ && coasted && coasted->uncertainty.status != IntegrityStatus::kLost;
  PoseUncertainty& u = report->uncertainty;
  auto report_coasted = [&]() {
    report->cam_from_world = coasted->cam_from_world;
    u = coasted->uncertainty;
    report->source = "odometry";
    anchor_ = coasted->anchor;
  };
  if (!report->cam_from_world) {
    if (!coasting) {
      if (coasted) {
        report->note += (report->note.empty() ? "" : "; ") + coasted->uncertainty.reason;
        report->uncertainty.reason = report->note;
      }
      anchor_.reset();
      return;
    }
    if (image_refutes_coasting_) {
      // The frame shows the robot elsewhere: the odometry's bound (no carry) no longer holds.
      report->note += (report->note.empty() ? "" : "; ") +
                      std::string(
                          "the image shows the robot away from the pose the odometry "
                          "carries: no coasted pose");
      report->uncertainty.reason = report->note;
      anchor_.reset();
      return;
    }
    const std::string image = report->note;
    report_coasted();
    report->status = TrackStatus::kCoasting;
    report->note = coasted->note + (image.empty() ? "" : "; image: " + image);
    // The odometry's bound holds for a robot that drove, not for one that was carried: the
    // coasted pose is tracking only when the frame's image does not contradict it (too few lines
    // to say, or the matcher finds a pose around it).
    if (!image_allows_coasting_ && u.status == IntegrityStatus::kTracking) {
      u.status = IntegrityStatus::kDegraded;
      const char* why = "the image does not show the pose the odometry carries";
      u.reason = u.reason.empty() ? why : why + ("; " + u.reason);
    }
    return;
  }
  // An unconfirmed matcher's pose: its levels are not trusted yet (ReacquisitionCheck).
  const bool reacquiring = reacquisition_.has_value();
  if (coasting) {
    const PoseDisagreement d =
        Disagreement(*report->cam_from_world, u, coasted->cam_from_world, coasted->uncertainty);
    if (d.contradicts) {
      u = UnionOfContradicting(u, coasted->uncertainty, d,
                               "the image pose is " + Fixed(d.position_m, 2) + " m / " +
                                   Fixed(RadToDeg(d.rotation_rad), 1) +
                                   " deg from the pose the odometry carries, beyond both levels (" +
                                   coasted->note + "): one of them is faulty");
      anchor_ = AnchorAtFix(*report->cam_from_world, u, now, frame_index_);
      return;
    }
    const bool coasted_tracking = coasted->uncertainty.status == IntegrityStatus::kTracking;
    if (reacquiring ? coasted_tracking : PreferCoasted(u, coasted->uncertainty)) {
      report_coasted();
      report->note = coasted->note + (reacquiring ? " (the matcher's pose agrees, unconfirmed)"
                                                  : " (the image pose agrees, with larger levels)");
      return;
    }
  }
  if (reacquiring) {
    // The coasted pose's bound holds whatever is reported: the chain goes on under it.
    if (coasting) {
      anchor_ = coasted->anchor;
    } else {
      anchor_.reset();
    }
    return;
  }
  anchor_ = AnchorAtFix(*report->cam_from_world, u, now, frame_index_);
}

}  // namespace linetrack

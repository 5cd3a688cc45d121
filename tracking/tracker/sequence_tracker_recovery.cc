// The tracking engine's recovery paths (sequence_tracker.h): the global mode of a lost or
// carried robot, and coasting on the odometry through frames without an image pose.
#include <string>

#include "models/text_format.h"
#include "tracking/tracker/planar_readings.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack {

void SequenceTracker::EnterGlobalMode(const std::string& why) {
  following_ = false;
  last_good_.reset();
  reacquisition_.reset();
  recent_projection_errors_.clear();
  recent_refined_rms_.clear();
  global_mode_ = true;
  global_reason_ = why;
  failed_searches_ = 0;
  anchor_.reset();  // the odometry carries the old pose, not the robot
}

void SequenceTracker::RequestGlobal() {
  start_pose_.reset();
  initial_prior_.reset();
  EnterGlobalMode("asked");
}

bool SequenceTracker::HasRival(const Eigen::Isometry3d& pose, const RobotReading& robot,
                               FrameReport* report) {
  const GlobalRecoveryOptions& o = options_.global;
  if (!global_ || !o.check_relocalisations || !ever_good_) return false;
  const GlobalAttempt g = global_->Attempt(*undistorted_, robot.height, robot.tilt);
  std::string rival;
  if (g.ambiguous) {
    rival = "the global mode finds the view ambiguous (" + std::to_string(g.rivals) + " rivals)";
  } else if (g.found) {
    const Eigen::Vector2d d = PlanarDifference(PlanarOf(g.cam_from_world), PlanarOf(pose));
    if (d[0] > o.rival_distance_m || d[1] > DegToRad(o.rival_heading_deg)) {
      rival = "the global mode finds a pose " + Fixed(d[0], 2) + " m / " +
              Fixed(RadToDeg(d[1]), 1) + " deg away";
    }
  }
  if (rival.empty()) return false;
  EnterGlobalMode("the matcher's pose near the prior has a rival: " + rival);
  report->cam_from_world.reset();
  report->source = "global";
  report->note = "global mode (" + global_reason_ + ")";
  return true;
}

void SequenceTracker::MaybeSwitchToGlobal(const RobotReading& robot) {
  if (global_mode_) return;
  LossState state;
  RobotPose prior;
  SearchBounds bounds;
  state.has_prior = relocalizer_ && MatcherPrior(robot, &prior, &bounds);
  state.frames_since_good = last_good_ ? FramesSinceGood() : static_cast<int>(frame_index_ + 1);
  state.failed_searches = failed_searches_;
  if (robot.odometry) state.driven_since_m = driven_m_ - (last_good_ ? last_good_->driven_m : 0.0);
  const std::string why = GlobalModeReason(state, options_.global);
  if (why.empty()) return;
  // The old pose and its statistics say nothing of where the robot is now.
  EnterGlobalMode(why);
}

bool SequenceTracker::TryGlobal(double t, const RobotReading& robot, FrameReport* report) {
  report->source = "global";
  const GlobalAttempt attempt = global_->Attempt(*undistorted_, robot.height, robot.tilt);
  report->lines = attempt.lines;
  const std::string mode = "global mode (" + global_reason_ + "): ";
  if (!attempt.found) {
    report->note = mode + attempt.reason;
    return false;
  }
  if (!StartAndVerify(attempt.cam_from_world, t, robot, report)) {
    report->note = mode + "its pose is not confirmed by the edges: " + report->note;
    return false;
  }
  return true;
}

void SequenceTracker::WithholdUnconfirmedGlobal(FrameReport* report) const {
  // Also a matcher's pose after the global mode dropped the last good pose: nothing before it
  // bounds a wrong answer either (global_reason_ is kept until a pose is confirmed).
  const bool unanchored = reacquisition_ && (reacquisition_->global ||
                                             (!global_reason_.empty() && !reacquisition_->before));
  if (!unanchored || !report->cam_from_world) return;
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

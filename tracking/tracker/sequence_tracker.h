// Tracking that starts and recovers by itself: each frame is undistorted and tracked with the
// moving edges; a pose is kept only when the tracker's health, the robot's known height and tilt
// and the motion since the last good pose agree. When lost, the next frames try to find the pose
// again (the matcher around the robot's prior with widening bounds, and a restart from the last
// good pose), and every candidate is verified by tracking it on its frame.
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <deque>
#include <optional>
#include <string>

#include "models/robot_pose.h"
#include "tracking/integrity/integrity_monitor.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/global_recovery.h"
#include "tracking/tracker/image_undistorter.h"
#include "tracking/tracker/odometry_coast.h"
#include "tracking/tracker/relocalizer.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack {

// The state of a frame, as frames.csv reports it.
enum class TrackStatus {
  kInitialising,  // no pose found yet (no pose)
  kTracking,      // pose followed from the previous frame, or the first pose (start file, matcher)
  kLost,          // the pose was lost or rejected on this frame and not found again (no pose)
  kRelocalised,   // the pose was found again after a loss (matcher or restart), verified
  kCoasting,      // no image pose: the last reported pose carried by the odometry
};

// "initialising", "tracking", "lost", "relocalised", "coasting".
const char* ToString(TrackStatus status);

// What a robot knows at a frame: its camera height and tilt (head encoders) and, with a prior
// file, the odometry's position and heading.
struct RobotReading {
  std::optional<Pose3Dof> odometry;
  double height = 0.0;  // metres
  double tilt = 0.0;    // radians, positive down
  double roll = 0.0;    // radians about the optical axis (RobotPose's; a mount's)
};

// A pose found by the matcher (the first one or after a loss) is reported degraded until it is
// confirmed: tracked over confirm_frames frames, its motion agreeing with the odometry's; with a
// good pose before the loss, it must also lie where the odometry carries that pose, within
// allowance_m + drift_share x the distance driven since, else it is confirmed only after
// confirm_distance_m more of consistent driving. A tracked pose whose motion since the matcher's
// pose departs from the odometry's by more than the allowance (and 3 sigma) is dropped.
struct ReacquisitionCheck {
  int confirm_frames = 5;
  double allowance_m = 0.10;
  double drift_share = 0.03;  // odometry drift per metre driven
  double heading_allowance_rad = 5.0 * kPi / 180.0;
  double confirm_distance_m = 2.0;

  bool Check(std::string* why) const;
};

// The reacquisition allowance (metres) after `driven_m` metres: allowance_m + drift_share driven.
double ReacquisitionAllowanceM(const ReacquisitionCheck& check, double driven_m);

struct SequenceTrackerOptions {
  // Each pose's covariance, protection levels and status (tracking, degraded, lost) from the
  // refinement's edges and points (tracking/integrity/, docs/integrity.md).
  IntegrityOptions integrity;
  ReacquisitionCheck reacquisition;
  // Coasting on the odometry (with a prior file): the frames without an image pose report the
  // last pose carried by the odometry, its levels grown by the odometry's stated bound; an image
  // pose is checked against the coasted one (odometry_coast.h, docs/integrity.md section 5.1).
  CoastOptions coast;
  HealthThresholds health;
  MotionLimits motion;
  RobotConstraint robot_tolerances;  // its height, tilt and roll are each frame's reading
  // After a loss, also try restarting the tracker from the last good pose (the only recovery of
  // a free camera; for a robot, tried after the matcher).
  bool restart_from_last_good = true;
  // A restart from the last good pose is tried only this many frames after it (the camera moves).
  int restart_window = 30;
  // With odometry, the last pose is moved by the odometry's motion since the last frame and
  // aligned on the image edges before tracking when that motion moves the model's image by more
  // than prediction_min_px (RMS over the model edges in view, RmsImageMotionPx).
  double prediction_min_px = 3.0;
  // A robot's pose must be confirmed by the sub-pixel refinement on the edges (with its height
  // and tilt); otherwise ViSP's unconstrained pose would be reported.
  bool robot_requires_refinement = true;
  // A jump of the projection error to more than jump_ratio times its median over the last
  // jump_window good frames (and above jump_floor_deg) means the edges latched onto other lines
  // (e.g. a door casing beside the modelled edge): the pose is dropped.
  double jump_ratio = 3.0;
  double jump_floor_deg = 8.0;
  int jump_window = 15;
  // Likewise, for a robot, the sub-pixel refinement's residual (rms_after): the model edges
  // fitting the image edges more than rms_jump_ratio times worse than over the last jump_window
  // good frames (and worse than rms_jump_floor_px) means some latched onto unmodelled lines and
  // pulled the pose while ViSP's own checks pass. A lower ratio refuses smaller pulls but also
  // good poses whose residual merely fluctuates (the trade-off: docs/tracking.md, health).
  double rms_jump_ratio = 2.5;
  double rms_jump_floor_px = 0.3;
  // When a lost robot switches to the global mode (with a GlobalRecovery: SetGlobalRecovery).
  GlobalRecoveryOptions global;

  bool Check(std::string* why) const;
};

// What happened on one frame.
struct FrameReport {
  TrackStatus status = TrackStatus::kInitialising;
  // The pose (the integrity monitor's when it has one): only for kTracking and kRelocalised, and
  // not when the integrity monitor finds the pose lost.
  std::optional<Eigen::Isometry3d> cam_from_world;
  // What may be done with the pose: tracking (within the alert limits), degraded, lost (no pose);
  // its covariance and protection levels.
  PoseUncertainty uncertainty;
  TrackHealth health;  // of the last tracking on this frame
  bool health_measured = false;
  // Where the pose came from: "tracker", "start pose", "matcher", "restart", "global", "odometry"
  // (coasted); on a frame without a pose, "global" when the global mode searched it.
  std::string source;
  std::string note;        // why there is no pose (empty otherwise)
  int lines = -1;          // segments extracted when the matcher ran, else -1
  bool predicted = false;  // tracking started from the odometry's prediction
  double undistort_ms = 0.0;
  double track_ms = 0.0;       // tracking from the previous frame, of which:
  double predict_ms = 0.0;     //   the odometry's prediction and its alignment on the edges
  double passes_ms = 0.0;      //   ViSP's track() passes
  double measure_ms = 0.0;     //   moving-edge states and sub-pixel refinement
  double relocalize_ms = 0.0;  // matcher, restarts and their verification
  double total_ms = 0.0;
};

class SequenceTracker {
 public:
  // `camera` is the camera of the incoming (distorted) frames; `tracker` must have been built
  // for its undistorted model. `relocalizer` may be null (free camera: no matcher). Both must
  // outlive the sequence tracker. Throws InputError on invalid options.
  SequenceTracker(EdgeTracker* tracker, const CameraIntrinsics& camera,
                  const Relocalizer* relocalizer, const SequenceTrackerOptions& options);

  // Start from this pose (ViSP pose file) on the next frame, before any matcher.
  void SetStartPose(const Eigen::Isometry3d& cam_from_world) { start_pose_ = cam_from_world; }

  // Prior of the first localisation of a robot without a prior file (x, y, heading).
  void SetInitialPrior(const Pose3Dof& prior) { initial_prior_ = prior; }

  // The global mode of a lost robot (null: none); it must outlive the sequence tracker.
  void SetGlobalRecovery(const GlobalRecovery* global) { global_ = global; }

  // Drops the pose and every prior: the next frames are localised by the global mode (when
  // there is one), each answer confirmed like a matcher's before it is `tracking`.
  void RequestGlobal();

  // Processes one frame taken at `t` seconds; `robot` is absent for a free camera.
  FrameReport Process(const vpImage<unsigned char>& image, double t,
                      const std::optional<RobotReading>& robot);

  // The last frame, undistorted (for overlays).
  const vpImage<unsigned char>& undistorted() const { return *undistorted_; }
  EdgeTracker& tracker() { return *tracker_; }
  int losses() const { return losses_; }
  const SequenceTrackerOptions& options() const { return options_; }
  int recoveries() const { return recoveries_; }
  // A matcher's pose is being confirmed (ReacquisitionCheck): its poses are reported degraded
  // until it is.
  bool reacquiring() const { return reacquisition_.has_value(); }
  // The frames are localised by the global mode until one of its poses is found.
  bool global_mode() const { return global_mode_; }

 private:
  struct GoodPose {
    Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
    double t = 0.0;
    std::optional<RobotReading> robot;  // what the robot read at that frame
    double driven_m = 0.0;              // odometry distance driven until that frame
  };

  // Empty when the tracked result can be kept at time t, else why not.
  std::string Judge(const EdgeTrackResult& result, double t,
                    const std::optional<RobotReading>& robot) const;
  // Starts the tracker at `candidate`, tracks the frame from there and judges the result.
  bool StartAndVerify(const Eigen::Isometry3d& candidate, double t,
                      const std::optional<RobotReading>& robot, FrameReport* report);
  // The matcher's prior for this frame (robot only) and its bounds; false when there is none.
  bool MatcherPrior(const RobotReading& robot, RobotPose* prior, SearchBounds* bounds) const;
  int FramesSinceGood() const { return static_cast<int>(frame_index_ - last_good_index_); }
  // The candidates of a frame not followed, in order (start pose, global mode, or the coasted
  // pose, the matcher and a restart), each verified by tracking: the source of the verified one,
  // else null.
  const char* Search(double t, const std::optional<RobotReading>& robot,
                     const std::optional<CoastedPose>& coasted, FrameReport* report);
  // Switches to the global mode when the loss calls for it (GlobalModeReason).
  void MaybeSwitchToGlobal(const RobotReading& robot);
  // Enters the global mode: the old pose, its reacquisition and jump statistics are dropped.
  void EnterGlobalMode(const std::string& why);
  // After a loss, the global mode's answer on the frame against the matcher's `pose`
  // (GlobalRecoveryOptions::check_relocalisations): true (and the global mode entered) when it
  // has a rival elsewhere or is ambiguous.
  bool HasRival(const Eigen::Isometry3d& pose, const RobotReading& robot, FrameReport* report);
  // Localises the frame with the global mode (this frame's probe_ when there is one) and verifies
  // its pose; false when none. A pose away from the one the global mode left is checked against
  // the image (HypothesisHolds).
  bool TryGlobal(double t, const RobotReading& robot, FrameReport* report);
  // In the global mode with no rival on the frame: the matcher around `hypothesis` (the pose the
  // mode left, carried `driven_m` metres), then a restart from it within the restart window.
  bool SearchAroundHypothesis(const Eigen::Isometry3d& hypothesis, double driven_m, double t,
                              const RobotReading& robot, FrameReport* report);
  // The image's evidence of a carry on a frame whose matcher found nothing around `prior` among
  // enough lines: the global mode's answer (ShowsElsewhere) counted into carry_frames_.
  void ProbeCarry(const RobotReading& robot, const Pose3Dof& prior);
  // On a frame the tracker lost, with a coasted pose: whether the image allows it (the matcher
  // finds a pose around it, or too few lines to say) or refutes it (ProbeCarry).
  void CheckCoasted(const RobotReading& robot, const CoastedPose& coasted);
  // On a frame tracking a global pose held against the pose the global mode left (a jump): the
  // matcher around that pose, carried; refuted on RefutationsNeeded() frames, it is dropped and
  // the jump with it.
  void RetestHypothesis(const RobotReading& robot);
  // Whether `pose` lies within the matcher's bounds around the pose the global mode left, carried
  // to `robot`'s reading (HypothesisBounds), that pose a confirmed one: it then bounds `pose` as a
  // last good pose would.
  bool AgreesWithGlobalBefore(const Eigen::Isometry3d& pose, const RobotReading& robot) const;
  // Counts one frame that refutes the pose the global mode left; true when it is dropped.
  bool RefuteHypothesis();
  int RefutationsNeeded() const;
  // Where the odometry carries the pose the global mode left (global_before_) to `robot`'s
  // reading; none without it or without odometry at both readings.
  std::optional<Eigen::Isometry3d> CarriedGlobalBefore(const RobotReading& robot) const;
  // True when this frame holds `hypothesis` (the pose the global mode left, carried): the tracker
  // verifies it, or the matcher finds a pose around it within the reacquisition allowance after
  // `driven_m` metres. Changes the tracker's state: the caller restarts it.
  bool HypothesisHolds(const Eigen::Isometry3d& hypothesis, double driven_m, double t,
                       const RobotReading& robot);
  // The frames' interval (seconds): the median of the last stamps' differences; 0 before two.
  double FramePeriod() const;
  // With odometry now and at the last frame: restarts the tracker from the predicted pose when
  // the predicted image motion is large.
  void MaybePredict(const std::optional<RobotReading>& robot, FrameReport* report);
  void Accept(const EdgeTrackResult& result, double t, const std::optional<RobotReading>& robot,
              const char* source, FrameReport* report);
  // Tracks the frame from the previous pose and judges the result (lost when it fails).
  void Follow(double t, const std::optional<RobotReading>& robot, FrameReport* report);
  // The pose's covariance, protection levels and status from its edge points (the reported pose
  // becomes the monitor's); then the reacquisition check of a matcher's pose.
  void Assess(const std::vector<EdgeObservation>& observations,
              const std::optional<RobotReading>& robot, FrameReport* report);
  // Starts (a matcher's pose; `started_after` points to the good pose before it) or continues the
  // reacquisition check; false when the tracked motion departs from the odometry's.
  bool CheckReacquisition(const std::optional<RobotReading>& robot,
                          const std::optional<GoodPose>* started_after, FrameReport* report);
  struct Reacquisition;
  // The check of a re-localised `pose` starting on this frame: its reference and the jump from
  // where the odometry carries it (beyond the allowance plus `sigma` metres).
  Reacquisition NewReacquisition(const Pose3Dof& pose, const std::optional<RobotReading>& robot,
                                 const std::optional<GoodPose>* started_after, double sigma) const;
  void Drop(const std::string& why, FrameReport* report);
  // The last reported pose carried to this frame by the odometry (none without an anchor or
  // odometry).
  std::optional<CoastedPose> CoastToFrame(const std::optional<RobotReading>& robot) const;
  // The image pose checked against the coasted one (a contradiction degrades it), or the coasted
  // pose reported when there is no image pose or it bounds the pose better; then the anchor the
  // next frame coasts from.
  // A global pose not yet confirmed is not reported: nothing before it bounds a wrong answer (a
  // twin corridor), so its covariance would not cover one. The tracker still follows it.
  void WithholdUnconfirmedGlobal(FrameReport* report) const;
  void Combine(const std::optional<RobotReading>& robot, const std::optional<CoastedPose>& coasted,
               FrameReport* report);

  // A matcher's pose being confirmed: the pose and the robot's reading at that frame, the frames
  // tracked since, and the good pose before it (restored when the check fails).
  struct Reacquisition {
    Pose3Dof pose;
    std::optional<RobotReading> robot;
    double driven_at_start_m = 0.0;
    int frames = 0;
    double needed_m = 0.0;  // distance to drive before confirmation
    double jump_m = 0.0;    // distance from where the odometry carries the good pose before
    std::string jump;       // that disagreement in words, when beyond the allowance
    std::optional<GoodPose> before;
    bool global = false;  // found by the global mode (no pose before it to compare)
    // The pose the re-localisation is compared with: the good pose before it, or for a global
    // pose the one the global mode left while the image has not refuted it.
    std::optional<GoodPose> reference;
    double jump_rad = 0.0;         // heading difference from the reference carried
    double episode_start_m = 0.0;  // odometry distance at the first re-localisation of the episode
  };

  EdgeTracker* tracker_;
  ImageUndistorter undistorter_;
  const Relocalizer* relocalizer_;
  const GlobalRecovery* global_ = nullptr;
  SequenceTrackerOptions options_;
  const vpImage<unsigned char>* undistorted_ = nullptr;
  vpImage<unsigned char> empty_;

  std::optional<Eigen::Isometry3d> start_pose_;
  std::optional<Pose3Dof> initial_prior_;
  std::optional<GoodPose> last_good_;
  // The pose the global mode left (the last good pose, or the matcher's pose the rival check
  // withheld): until the image refutes it (a carry) or a pose is confirmed, where the odometry
  // carries it may be the truth, and a global answer away from it carries the jump in its
  // covariance until confirmed by driving (ReacquisitionCheck::confirm_distance_m).
  std::optional<GoodPose> global_before_;
  // global_before_ was a confirmed pose (not a re-localisation under confirmation, not the
  // matcher's pose the rival check withheld): only then does it bound a pose that agrees with it.
  bool global_before_confirmed_ = false;
  std::optional<Reacquisition> reacquisition_;
  std::optional<Pose3Dof> last_odometry_;
  std::optional<CoastAnchor> anchor_;  // the last reported pose with finite levels
  double driven_m_ = 0.0;              // odometry distance driven since the first frame
  std::vector<EdgeObservation> verified_observations_;  // of the last StartAndVerify
  std::deque<double> recent_projection_errors_;         // of the last good frames
  std::deque<double> recent_refined_rms_;  // refinement residuals of the last good frames
  bool following_ = false;                 // the tracker holds a good pose from the previous frame
  bool ever_good_ = false;                 // a pose was accepted on some frame
  bool global_mode_ = false;               // lost frames are localised by the global mode
  // This frame's matcher found a pose around the prior, or saw too few lines to contradict it.
  bool image_allows_coasting_ = false;
  // This frame shows the robot away from the pose the odometry carries (ProbeCarry).
  bool image_refutes_coasting_ = false;
  std::optional<GlobalAttempt> probe_;  // this frame's global answer (ProbeCarry)
  int carry_frames_ = 0;  // frames showing the robot elsewhere (GlobalRecoveryOptions)
  std::optional<GoodPose> carry_seen_;   // the last pose they found
  int hypothesis_refutations_ = 0;       // frames in a row refuting global_before_
  std::string global_reason_;            // why the global mode was entered
  long frame_index_ = -1;                // frames processed - 1
  double t_ = 0.0;                       // this frame's stamp (seconds)
  std::deque<double> recent_intervals_;  // the last stamps' differences (seconds)
  long last_good_index_ = -1;
  int losses_ = 0;
  int recoveries_ = 0;
};

}  // namespace linetrack

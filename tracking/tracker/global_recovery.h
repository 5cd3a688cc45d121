// Kidnapped-robot recovery of the tracking engine: when the prior the odometry carries from the
// last good pose has grown past its use (lost too long, or driven too far since), or the robot
// was carried away (frames that show the building disagree with the carried prior: neither the
// tracker nor the matcher around it finds a pose), the frames are localised by the global mode
// (matching/global/: any position in the navigable area, any heading) instead of the matcher around
// that prior. docs/global.md, "Kidnapped-robot recovery".
#pragma once

#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <string>

#include "matching/global/global_localizer.h"
#include "matching/lines/line_extractor.h"
#include "models/robot_pose.h"

namespace linetrack {

// When a lost robot switches to the global mode (a trigger at 0 is off). The triggers are times
// and distances; the engine turns the times into frame counts with the frame interval it reads
// from the frames' stamps (FramesIn), so that they mean the same at any frame rate.
struct GlobalRecoveryOptions {
  // The engine builds the global mode (for these triggers and SequenceTracker::RequestGlobal).
  bool enabled = true;
  // The robot was carried away (the odometry does not see a carry) when the frames of kidnap_s
  // seconds, and at least kidnap_min_frames, show it elsewhere: on each, the matcher around the
  // carried prior finds nothing among at least kidnap_min_lines segments, and the global mode
  // finds a pose away from that prior or an ambiguous view with no rival near it
  // (ShowsElsewhere), the poses found agreeing with each other. A frame neither places (blurred,
  // blank) leaves the count as it is; a pose found near the prior resets it.
  double kidnap_s = 0.3;
  int kidnap_min_lines = 8;
  int kidnap_min_frames = 2;
  // Lost for lost_s seconds (the relocaliser's widening bounds reach their limit after 24 frames
  // of 0.1 s by default) or lost_distance_m metres driven since the last good pose.
  double lost_s = 2.5;
  double lost_distance_m = 3.0;
  // A re-localisation by the matcher near the carried prior is checked by the global mode: an
  // ambiguous answer, or a pose farther than rival_distance_m or rival_heading_deg from the
  // matcher's, means the view repeats elsewhere (a carried robot may stand in the twin of the
  // corridor it left): the matcher's pose is withheld and the global mode takes over.
  bool check_relocalisations = true;
  double rival_distance_m = 0.5;
  double rival_heading_deg = 10.0;

  bool Check(std::string* why) const;
};

// The frames that cover `seconds` at one frame every `period_s` seconds (at least 1); 0 when
// `seconds` is 0 (the trigger is off) or the period is not known yet (period_s <= 0).
int FramesIn(double seconds, double period_s);

// A lost robot's situation on one frame.
struct LossState {
  bool has_prior = false;        // there is a prior for the matcher (a good pose, odometry, ...)
  int frames_since_good = 0;     // frames since the last good pose
  int carry_frames = 0;          // frames that showed the robot away from the prior (kidnap_s)
  double driven_since_m = -1.0;  // odometry distance since the last good pose; < 0: no odometry
  double frame_period_s = 0.0;   // the frames' interval from their stamps; <= 0: not known yet
};

// The frames that show a carry (kidnap_s, at least kidnap_min_frames) at one frame every
// `period_s` seconds; 0 when the trigger is off or the period not known yet.
int CarryFrames(const GlobalRecoveryOptions& options, double period_s);

// Why this frame needs the global mode (pure), or empty when the local matcher keeps searching.
std::string GlobalModeReason(const LossState& state, const GlobalRecoveryOptions& options);

// One global localisation of a frame.
struct GlobalAttempt {
  bool found = false;      // one pose, not ambiguous
  bool ambiguous = false;  // rival poses explain the image equally well: none is used
  int rivals = 0;
  std::vector<Pose3Dof> rival_poses;  // when ambiguous (x, y metres, heading radians)
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();  // when found
  Pose3Dof planar;                                                   // its x, y, heading
  int lines = 0;                                                     // segments extracted
  double ms = 0.0;
  std::string reason;  // why no pose
};

// Whether the global mode's answer shows the robot away from `prior`: a pose found beyond
// options.rival_distance_m or rival_heading_deg from it, or an ambiguous view none of whose
// rivals lies within those.
bool ShowsElsewhere(const GlobalAttempt& attempt, const Pose3Dof& prior,
                    const GlobalRecoveryOptions& options);

class GlobalRecovery {
 public:
  // `global` must outlive this object; `extractor` gives the segments of an undistorted frame;
  // fewer than `min_lines` segments: no attempt. Throws InputError when there is no extractor.
  GlobalRecovery(const GlobalLocalizer& global, LineExtractorFunction extractor, int min_lines);

  // Localises the undistorted frame with no prior: the camera's height (metres) and tilt
  // (radians, positive down) known. An ambiguous answer is not found.
  GlobalAttempt Attempt(const vpImage<unsigned char>& undistorted, double height,
                        double tilt) const;

 private:
  const GlobalLocalizer& global_;
  LineExtractorFunction extractor_;
  int min_lines_;
};

}  // namespace linetrack

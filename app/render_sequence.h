// The sequence form of `linetrack render`: the frames (a TUM trajectory, the hall loop or a
// waypoint path), the odometry priors, the drive's effects, and the files of the sequence folder.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "models/navigable_area.h"
#include "models/render/drive_effects.h"
#include "models/render/kidnap.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "models/render/waypoint_path.h"
#include "models/trajectory_io.h"
#include "models/wireframe.h"

namespace linetrack::app {

// The generated loop's name for --path.
inline constexpr const char* kHallLoopPath = "hall-loop";

// Flags of a sequence (angles in degrees as on the command line).
struct RenderSequenceOptions {
  std::string trajectory, path;  // one of them
  int frames = 0;                // 0: all of the trajectory, one lap, or the whole path
  DriveOptions drive;            // speed, fps and the periods (angles from the fields below)
  double height = 1.3, tilt_deg = 5.0;
  double pan_amplitude_deg = 0.0, pan_rate_deg = 0.0, tilt_amplitude_deg = 0.0;
  LoopPathOptions loop;
  WaypointPathOptions waypoints;
  DriveEffectsOptions effects;  // its seed is `seed`
  double odometry_drift_percent = 0.0;
  bool drift_given = false;  // odometry from OdometryForDrift, else OdometryOptions' defaults
  std::vector<std::string> kidnap_texts;  // --kidnap FRAME:x,y,heading_deg, repeated
  std::vector<Kidnap> kidnaps;            // parsed by CheckSequenceFlags
  uint64_t seed = 1;
};

// Throws InputError naming the flag when a value is out of range; parses the kidnaps.
void CheckSequenceFlags(RenderSequenceOptions* options);

// A sequence ready to render.
struct RenderedSequence {
  std::vector<SequenceFrame> frames;
  std::vector<PriorRecord> priors;
  DriveEffects effects;
  DriveEffectsOptions effects_options;
  OdometryDrift drift;       // measured over 10 m windows
  double drift_asked = 0.0;  // share; 0 when not asked
  std::vector<Kidnap> kidnaps;
};

// The frames, priors and effects of the sequence (nothing written); with kidnaps, the odometry
// is simulated from the drive without them (the carried robot's wheels do not turn). `area` is
// needed for the hall loop and checks waypoint paths and where people cross (may be null
// otherwise). Throws InputError on bad files or values.
RenderedSequence PrepareSequence(const RenderSequenceOptions& options, const NavigableArea* area);

// Renders every frame into `out` (frame_%05d.png) and writes groundtruth.txt, priors.csv,
// camera.xml (undistorted when `undistorted`), frame_truth.csv and sequence.json; progress on
// stderr, a summary on stdout.
void WriteSequence(const std::string& out, const WireframeModel& model, SceneRenderer* renderer,
                   bool undistorted, RenderedSequence* sequence);

}  // namespace linetrack::app

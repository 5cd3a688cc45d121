// Cost of linetrack's per-frame tracking step beside ViSP's bare vpMbGenericTracker::track() on
// the same frames in the same run, and replay throughput. The body of `linetrack bench track`.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "models/camera.h"
#include "tracking/tracker/tracker_settings.h"

namespace linetrack::app {

// A recorded sequence with a start pose, as ViSP's samples provide them.
struct BenchSequence {
  std::string name;
  std::string images;         // printf pattern of the frames
  std::string model;          // .cao for both trackers
  std::string visp_settings;  // ViSP XML the bare tracker loads (loadConfigFile)
  CameraIntrinsics camera;    // the frames' camera (with its size)
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();  // cam_from_world of the first frame
  TrackerSettings settings;                                 // linetrack's settings
};

// The .cao text of Castle-simu's scene as ViSP's own regression test models it: the castle and the
// textured cube beside it (testGenericTracker.cpp's transform), included from `castle_folder`
// (tests/data/visp/castle_simu_scene.cao holds the same for the Debian path).
std::string CastleSimuSceneCao(const std::string& castle_folder);

// The visp-images-data sequences of the bench: mbt/cube, mbt-depth/Castle-simu (scene model
// written into `scratch_dir`) and mbt-depth/castel when present. `visp_images` is the ViSP-images
// folder. Sequences whose files are missing are skipped.
std::vector<BenchSequence> VispBenchSequences(const std::string& visp_images,
                                              const std::string& scratch_dir);

struct TrackBenchResult {
  std::string name;
  int frames = 0;             // frames after the first (the start frame is not timed)
  int visp_tracked = 0;       // frames ViSP's bare tracker got through before throwing
  int linetrack_tracked = 0;  // frames linetrack reported tracking
  // Per frame, wall clock and CPU time of the calling thread (milliseconds): ViSP's track() on
  // the frames it tracked, linetrack's Process() (undistortion, passes, health) on every frame.
  std::vector<double> visp_ms, visp_cpu_ms;
  std::vector<double> linetrack_ms, linetrack_cpu_ms;
  // Wall clock of two stages of linetrack's step (FrameReport): ViSP's passes, and the moving-edge
  // states with the sub-pixel refinement.
  std::vector<double> passes_ms, measure_ms;
  double replay_fps = 0.0;     // frames / s through decoding and Process(), no encoding
  double replay_passes = 0.0;  // mean tracking passes per frame in the replay run
};

// Runs both trackers over the preloaded frames of `sequence` `repeats` times (per-frame times
// pooled), then one replay pass that decodes every frame from disk. Throws InputError when a file
// is missing.
TrackBenchResult RunTrackBench(const BenchSequence& sequence, int repeats);

}  // namespace linetrack::app

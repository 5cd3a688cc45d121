// Synthetic localisation scenes after Ait Aider, Hoppenot, Colle (RAS 2005, section 4.1): random
// robot camera poses in the navigable area, the visible model edges projected with a calibration
// error, line noise (Table 1) and fragmentation, unmodelled clutter lines, and a rough prior
// drawn within the bounds of Table 2. Deterministic from a seed; see docs/synth.md.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/wireframe.h"

namespace linetrack {

// The paper's synthetic camera: 640x480 px, px = py = 1000 px, (u0, v0) = (320, 240) with u the
// column (the paper writes u0 = 240, v0 = 320 with u the row), no distortion.
CameraIntrinsics PaperSyntheticCamera();

// Prior bounds of the paper's Table 2: QI 1, 2, 3 -> delta_t 0.30 / 0.50 / 0.75 m and
// delta_phi 10 / 15 / 20 degrees (returned in radians). Throws InputError for another index.
struct PriorBounds {
  double delta_t = 0.0;    // metres
  double delta_phi = 0.0;  // radians
};
PriorBounds QualityIndexBounds(int qi);

struct SyntheticSceneOptions {
  uint64_t seed = 1;
  int count = 430;
  // Pose ranges: height of the optical centre above the floor (metres) and tilt below the
  // horizontal (radians).
  double height_min = 1.2, height_max = 1.5;
  // The storey the camera stands on (an index into the area's storeys; poses are drawn in its
  // parts) and the world z of its floor: scenes' heights are floor_z + the drawn height.
  int storey = 0;
  double floor_z = 0.0;
  double tilt_min = 0.0, tilt_max = DegToRad(10.0);
  // The nominal camera (what the case gives the matcher); the image is generated with
  // px, py scaled by (1 + eps_m), eps_m ~ N(0, calibration_sigma) per scene (Table 1, eta_m).
  CameraIntrinsics camera = PaperSyntheticCamera();
  double calibration_sigma = 0.02;
  // Line noise per image segment (Table 1, eta_rho and eta_d): rotation about its midpoint by
  // N(0, angle_sigma) radians, then a shift along its normal by N(0, offset_sigma_px) pixels.
  double angle_sigma = DegToRad(1.0);
  double offset_sigma_px = 3.0;
  // Fragmentation: each end shortened along the line by U(0, shorten_max) of its length; with
  // probability split_probability the segment is cut in two at U(0.25, 0.75) of its length with
  // a gap of U(0, split_gap) of its length.
  double shorten_max = 0.15;
  double split_probability = 0.2;
  double split_gap = 0.15;
  // Image segments shorter than this (pixels) are dropped, model lines and clutter alike.
  double min_length_px = 15.0;
  // Accepted count of visible model edges per scene (edges with at least one image line after
  // noise and fragmentation: the paper's "model segments viewed"); poses outside are redrawn,
  // at most max_attempts times per scene. Fragmentation can give an edge two lines.
  int min_visible_edges = 5, max_visible_edges = 12;
  int max_attempts = 20000;
  // Clutter lines per scene, U{min, max}; round(count * vertical_clutter_fraction) of them are
  // images of unmodelled vertical 3D segments standing on the floor (furniture legs, stands)
  // at vertical_clutter_distance metres in front of the camera, vertical_clutter_height tall;
  // the others random image segments clutter_length_px long.
  int min_clutter = 5, max_clutter = 12;
  double vertical_clutter_fraction = 1.0 / 3.0;
  double vertical_clutter_distance_min = 1.0, vertical_clutter_distance_max = 6.0;
  double vertical_clutter_height_min = 0.3, vertical_clutter_height_max = 1.5;
  double clutter_length_min_px = 20.0, clutter_length_max_px = 200.0;
  // Near-parallel unmodelled lines (door casings, boxes against walls): parallel_clutter lines
  // per scene, each beside a model line of the scene (chosen uniformly) at a perpendicular
  // offset U(parallel_offset_min_px, parallel_offset_max_px) on a random side, over a random
  // stretch (U(0.3, 1) of it), with their own line noise. Drawn from a separate random stream:
  // with 0 (the default) the scenes are those without the option.
  int parallel_clutter = 0;
  double parallel_offset_min_px = 2.0, parallel_offset_max_px = 8.0;
  // Prior bounds (default QI1); the prior position is uniform in the disk of radius delta_t
  // around the truth, the prior heading uniform within +-delta_phi of the true heading.
  double delta_t = 0.30;
  double delta_phi = DegToRad(10.0);

  // Finite values, ordered ranges, noise >= 0, a camera with a known image size, delta_phi in
  // (0, pi] (what the matcher accepts).
  bool Check(std::string* why) const;
};

// One generated case with its ground truth.
struct SyntheticScene {
  int index = 0;                // position in the series (the per-scene random stream)
  std::vector<Segment2> lines;  // undistorted pixels (u = column), model lines and clutter mixed
  Pose3Dof prior;               // x, y (metres), heading (radians)
  double delta_t = 0.0;         // metres
  double delta_phi = 0.0;       // radians
  double height = 0.0;  // world z of the optical centre, metres (true, known to the matcher)
  double tilt = 0.0;    // radians (true, known to the matcher)
  RobotPose truth;
  std::vector<std::pair<int, int>> matches;  // (model edge id, line index), sorted
  std::vector<int> clutter;                  // indices of clutter lines, sorted
  std::vector<int> vertical_clutter;         // those of them that image vertical 3D segments
  double calibration_error = 0.0;            // eps_m: image focal lengths are (1 + eps_m) px, py
  int attempts = 0;                          // poses drawn until this one was accepted
};

// Scene `index` of the series defined by `options` (its own random stream seeded from
// (options.seed, index), so a scene does not depend on `count`). Throws InputError when the
// options are invalid or no pose gives an accepted scene within max_attempts.
SyntheticScene GenerateScene(const WireframeModel& model, const OcclusionTester& occlusion,
                             const NavigableArea& area, const SyntheticSceneOptions& options,
                             int index);

// Scenes 0 .. options.count - 1.
std::vector<SyntheticScene> GenerateScenes(const WireframeModel& model, const NavigableArea& area,
                                           const SyntheticSceneOptions& options);

// --- Pure pieces of the noise model, exposed for tests ---

// Portable random draws from a std::mt19937_64 (the engine's output is fixed by the standard;
// the draws below are our own formulas, so scenes are identical across standard libraries).
class SceneRandom {
 public:
  // Seeded through std::seed_seq from (seed, stream).
  SceneRandom(uint64_t seed, uint64_t stream);
  double Uniform(double lo, double hi);  // [lo, hi), 53-bit resolution
  double Normal(double sigma);           // N(0, sigma) by Box-Muller; always draws
  int Integer(int lo, int hi);           // uniform in {lo, ..., hi}
  bool Bernoulli(double p);

 private:
  std::mt19937_64 engine_;
};

// Rotates `s` about its midpoint by `angle` (radians, counter-clockwise in (u, v)), then shifts
// it by `offset` pixels along its unit normal (direction rotated by +90 degrees).
Segment2 PerturbSegment(const Segment2& s, double angle, double offset);

// Shortens `s` by the fractions `cut_a`, `cut_b` of its length at its two ends; when `gap` > 0
// removes [split - gap / 2, split + gap / 2] (fractions of the original length) too, giving
// two pieces. Pieces of non-positive length are dropped.
std::vector<Segment2> FragmentSegment(const Segment2& s, double cut_a, double cut_b, double split,
                                      double gap);

}  // namespace linetrack

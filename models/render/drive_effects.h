// What makes a rendered drive hard, scheduled from a seed over the drive's time: people crossing
// close in front of the camera, the lens covered (blackouts), exposure changes (gain steps and
// ramps) and motion blur over the shutter time.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/render/people.h"
#include "models/render/sequence.h"

namespace linetrack {

struct DriveEffectsOptions {
  uint64_t seed = 1;
  int people = 0;                         // people crossing in front of the camera
  double person_distance_min = 0.9;       // metres in front of the camera where they cross its axis
  double person_distance_max = 2.0;       //
  double person_speed = 1.3;              // m/s
  double person_walk_half = 3.0;          // metres walked before and after crossing the axis
  int blackouts = 0;                      // times the lens is covered
  double blackout_duration = 0.6;         // seconds
  int exposure_changes = 0;               // gain changes, alternately steps and ramps
  double gain_min = 0.5, gain_max = 1.6;  // range of the gain levels (log-uniform)
  double ramp_duration = 2.0;             // seconds of a gain ramp
  double shutter = 0.0;                   // exposure time (seconds): motion blur; 0 for none
  double blur_step_px = 2.0;              // image motion between two shutter samples (pixels)
  int max_shutter_samples = 8;            //

  bool Check(std::string* why) const;
};

// A gain level from a time on (piecewise linear between knots, constant outside).
struct GainKnot {
  double t = 0.0;
  double gain = 1.0;
};

struct DriveEffects {
  std::vector<PersonWalk> people;
  std::vector<double> person_crossing_t;             // when each crosses the camera's axis
  std::vector<std::pair<double, double>> blackouts;  // [start, end) seconds
  std::vector<GainKnot> gain;                        // sorted by time

  double GainAt(double t) const;
  bool CoveredAt(double t) const;
  // The surfaces of every person in the scene at time t.
  std::vector<RenderSurface> PeopleAt(double t) const;
};

// Schedules the effects over the frames' time span. Event k of each kind lies in the k-th of
// equal time slots (uniformly in its middle half). A person crosses the optical axis of the
// frame nearest its time at a seeded distance, walking across it (left or right) from
// `person_walk_half` metres before to as far after; with `area`, the crossing point must be in
// sight within it (else shorter distances, then neighbouring frames, are tried; a person that
// fits nowhere is left out) and the walk ends 0.5 m past the area (inside the wall there, as
// if through a doorway). A blackout's frames are covered; gains alternate steps and ramps to new
// levels.
DriveEffects PlanDriveEffects(const std::vector<SequenceFrame>& frames,
                              const DriveEffectsOptions& options,
                              const NavigableArea* area = nullptr);

// Interpolated camera pose at time t (camera centre linear, rotation slerp between the two
// frames around t; clamped to the first and last frame).
Eigen::Isometry3d CamFromWorldAt(const std::vector<SequenceFrame>& frames, double t);

// Largest displacement (pixels) of a 3 x 3 grid of image points seen at 2 m depth from pose a
// when seen from pose b (pinhole of `camera`): how far the image moves from a to b.
double ImageMotionPx(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                     const CameraIntrinsics& camera);

// Poses across the shutter of frame k (centred on its time): one pose without a shutter time,
// else ceil(motion / blur_step_px) samples (1 to max_shutter_samples) spread evenly over it;
// *motion_px (may be null) gets the image motion over the shutter.
std::vector<Eigen::Isometry3d> ShutterPoses(const std::vector<SequenceFrame>& frames, size_t k,
                                            const CameraIntrinsics& camera,
                                            const DriveEffectsOptions& options,
                                            double* motion_px = nullptr);

}  // namespace linetrack

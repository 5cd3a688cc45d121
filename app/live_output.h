// Output folder of `linetrack live`, written as frames complete so that an interrupted run leaves
// valid files: frames.csv (the head log: one row per iteration, flushed), poses.txt (TUM,
// world_from_cam, frames with a pose), truth.txt (simulation: the true camera poses),
// snapshots/frame_NNNNN.png (overlays) and summary.json (written last, atomically).
#pragma once

#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>

#include <Eigen/Geometry>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/integrity_output.h"
#include "tracking/live/live_loop.h"

namespace linetrack::app {

// The header of frames.csv (status: tracking, degraded, lost; state: the tracker's).
extern const char* const kLiveCsvHeader;

// One row of frames.csv for `it` (angles and rates in degrees, errors in pixels, times in ms).
std::string LiveCsvRow(const LiveIteration& it);

class LiveOutput {
 public:
  // Creates `dir` and its files with their headers (replacing those of an earlier run). Throws
  // InputError when the folder or a file cannot be written.
  // poses.txt holds the poses tracking, or all of them with `all_poses`.
  LiveOutput(const std::string& dir, bool with_truth, bool all_poses);

  // Appends the iteration's row and covariance line (and its pose, and the true pose when
  // given); flushed.
  void Add(const LiveIteration& it, const Eigen::Isometry3d* true_cam_from_world);

  // Writes snapshots/frame_NNNNN.png (atomically: a temporary name renamed into place).
  void Snapshot(std::int64_t frame, const vpImage<vpRGBa>& image);

  // Writes summary.json atomically.
  void Finish(const nlohmann::ordered_json& summary);

  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  std::ofstream frames_, poses_, truth_;
  std::unique_ptr<CovarianceLog> covariance_;
  bool all_poses_ = false;
};

}  // namespace linetrack::app

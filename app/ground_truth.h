// Ground truth for `replay`: a TUM trajectory (by time) or a printf pattern of ViSP pose files (by
// frame number), as `--ground-truth` names it.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "models/trajectory_io.h"
#include "tracking/capture/video_source.h"

namespace linetrack::app {

class GroundTruth {
 public:
  // `spec` empty: no ground truth. Throws InputError when the file or pattern gives no pose.
  explicit GroundTruth(const std::string& spec);
  bool enabled() const { return !spec_.empty(); }
  // The TUM file's times (seconds); empty for pose files.
  std::vector<double> Times() const;
  // cam_from_world of frame `frame` taken at `t`; tolerance in seconds for TUM files.
  std::optional<Eigen::Isometry3d> At(long frame, double t, double tolerance) const;

 private:
  std::string spec_;
  SequencePattern pattern_;
  bool by_frame_ = false;
  std::vector<StampedPose> poses_;
};

}  // namespace linetrack::app

#include "app/ground_truth.h"

#include <filesystem>

#include "models/errors.h"
#include "tracking/tracker/pose_file.h"
#include "tracking/tracker/robot_readings.h"

namespace linetrack::app {

GroundTruth::GroundTruth(const std::string& spec) : spec_(spec) {
  if (spec.empty()) return;
  if (ParseSequencePattern(spec, &pattern_)) {
    long first = 0, last = 0;
    if (!FindSequenceRange(pattern_, &first, &last)) {
      throw InputError(spec + ": --ground-truth: no pose file matches the pattern");
    }
    by_frame_ = true;
  } else {
    poses_ = ReadTum(spec);
    if (poses_.empty()) throw InputError(spec + ": --ground-truth: no poses");
  }
}

std::vector<double> GroundTruth::Times() const {
  std::vector<double> times;
  for (const StampedPose& p : poses_)
    times.push_back(p.t);
  return times;
}

std::optional<Eigen::Isometry3d> GroundTruth::At(long frame, double t, double tolerance) const {
  if (!by_frame_) return GroundTruthAt(poses_, t, tolerance);
  const std::string path =
      (std::filesystem::path(pattern_.directory) / SequenceFileName(pattern_, frame)).string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  return ReadPoseFile(path);
}

}  // namespace linetrack::app

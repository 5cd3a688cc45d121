// The camera's geometry on the pan-tilt head as `live` and `replay` believe it: the nominal
// geometry of --head-model, or the calibrated mount of --mount mount.json
// (calibration/mount_file.h), with the base's tilt when the file has a floor calibration; and the
// height of the axes' crossing: the mount file's floor calibration, else the camera height taped
// with the head level (--height) through the geometry.
#pragma once

#include <optional>
#include <string>

#include "calibration/mount_file.h"
#include "models/robot_pose.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack::app {

struct BelievedHead {
  HeadGeometry geometry;
  double crossing_height = 0.0;  // metres above the floor
  std::string description;       // for logs and summaries
};

// The geometry and crossing height from the flags. `taped_height` (the camera centre above the
// floor, head level) is used when the mount file has no floor calibration; throws InputError
// naming --height when it is then missing.
BelievedHead BelieveHead(HeadModel model, const std::optional<MountFile>& mount,
                         const std::string& mount_path, std::optional<double> taped_height);

// `reading` with the height, tilt and roll of the camera's centre and optical axis on the head at
// pan 0 and `head_tilt` (none depends on the base's position or heading); its odometry is kept.
RobotReading ReadingOnHead(const BelievedHead& head, RobotReading reading, double head_tilt);

}  // namespace linetrack::app

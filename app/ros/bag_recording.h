// rosbag files as `replay` inputs (app/recording.h), through the rosbag C++ API: the images of a
// topic (stamped with their header stamps), the odometry as the prior file (interpolated at each
// image's stamp by replay), the head's joint states, the camera_info; the replayed poses
// (PoseWithCovarianceStamped) and map -> odom (TF) written into a new bag.
#pragma once

#include <memory>
#include <string>

#include "app/recording.h"

namespace linetrack::app {

// Opens and checks `path`: unreadable, truncated or unindexed bags, a missing topic and a topic of
// the wrong message type throw InputError naming the file and topic, before any output exists.
std::unique_ptr<Recording> OpenRosBag(const std::string& path, const RecordingOptions& options);

}  // namespace linetrack::app

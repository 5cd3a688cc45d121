#include "app/head_mount.h"

#include <cstdio>

#include "models/errors.h"
#include "models/pan_tilt.h"
#include "tracking/head/head_pointing.h"

namespace linetrack::app {

BelievedHead BelieveHead(HeadModel model, const std::optional<MountFile>& mount,
                         const std::string& mount_path, std::optional<double> taped_height) {
  BelievedHead head;
  head.geometry = GeometryOf(model);
  head.description = model == HeadModel::kPtu46 ? "nominal ptu46" : "nominal biclops";
  if (mount) {
    head.geometry.tilt_from_camera = mount->tilt_from_camera;
    head.description = "calibrated mount " + mount_path;
    if (mount->floor) {
      head.geometry.level_from_base =
          LevelFromBaseRotation(mount->floor->base_roll, mount->floor->base_pitch);
    }
  }
  std::string why;
  if (!head.geometry.Check(&why)) throw InputError(Located(mount_path, 0, why));
  if (mount && mount->floor) {
    head.crossing_height = mount->floor->crossing_height;
    head.description += " with its floor height";
    return head;
  }
  if (!taped_height) {
    throw InputError(mount ? "--height: needed (" + mount_path + " has no floor calibration)"
                           : std::string("--height: needed (the camera height, head level)"));
  }
  head.crossing_height = CrossingHeightFor(head.geometry, *taped_height);
  char taped[64];
  std::snprintf(taped, sizeof(taped), " and a taped height of %.3f m", *taped_height);
  head.description += taped;
  return head;
}

RobotReading ReadingOnHead(const BelievedHead& head, RobotReading reading, double head_tilt) {
  const RobotPose camera =
      CameraPoseOnHead(head.geometry, Pose3Dof{}, head.crossing_height, 0.0, head_tilt);
  reading.height = camera.height;
  reading.tilt = camera.tilt;
  reading.roll = camera.roll;
  return reading;
}

}  // namespace linetrack::app

// The calibrated head of the ROS mount tests (`linetrack ros --mount`, `replay --input RUN.bag
// --mount`): a camera off the nominal PTU-46 geometry on a tilted base, and its mount.json as
// calibrate-mount writes it.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <string>

#include "calibration/mount_file.h"
#include "models/pan_tilt.h"
#include "tests/app/ros_test_scene.h"
#include "tracking/head/head_kinematics.h"

namespace linetrack::test {

// The camera 76.5 mm left of and 68 mm above the axes' crossing (ViSP's PTU-46) but turned 1.2
// degrees in yaw and 1 degree in pitch off the tilt frame's axes, on a base tilted 0.5 degrees in
// pitch and -0.3 in roll; the crossing 1.232 m above the floor.
constexpr double kMountYawDeg = 1.2;
constexpr double kMountPitchDeg = 1.0;
constexpr double kBasePitchDeg = 0.5;
constexpr double kBaseRollDeg = -0.3;
constexpr double kCrossingHeightM = kSceneHeight - 0.068;

inline HeadGeometry CalibratedHead() {
  HeadGeometry head;
  head.tilt_from_camera = AlignedMount(Eigen::Vector3d(0.0, 0.0765, 0.068), CameraRoll::kUpright);
  head.tilt_from_camera.linear() =
      (Eigen::AngleAxisd(DegToRad(kMountYawDeg), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(DegToRad(kMountPitchDeg), Eigen::Vector3d::UnitY()))
          .toRotationMatrix() *
      head.tilt_from_camera.linear();
  head.level_from_base = LevelFromBaseRotation(DegToRad(kBaseRollDeg), DegToRad(kBasePitchDeg));
  return head;
}

// mount.json of `head` as calibrate-mount writes it for `camera_path`, with a floor calibration
// (the crossing's height and the base's tilt), in `dir`; returns its path.
inline std::string WriteMountJson(const HeadGeometry& head, const std::string& camera_path,
                                  const std::filesystem::path& dir) {
  MountCalibration calibration;
  calibration.status = MountStatus::kOk;
  calibration.tilt_from_camera = head.tilt_from_camera;
  calibration.covariance.diagonal().setConstant(1e-8);
  MountRunInfo info;
  info.camera_path = camera_path;
  FloorCalibration floor;
  floor.ok = true;
  floor.floor = {kCrossingHeightM, DegToRad(kBaseRollDeg), DegToRad(kBasePitchDeg)};
  info.floor = floor;
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "mount.json").string();
  std::ofstream(path) << MountJson(calibration, info);
  return path;
}

}  // namespace linetrack::test

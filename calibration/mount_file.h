// The files of the mount calibration (docs/calibration.md):
//   ANGLES.csv  `image,pan_deg,tilt_deg`: the head's angles at which each image was taken;
//   mount.json  the camera's mount on the head (tilt_from_camera, 4x4 row-major, metres), its 6x6
//               covariance, the RMS reprojection error, the views used and rejected, and, with a
//               floor board, the axes' crossing height above the floor and the base's tilt. Read
//               back by `live` and `replay` (--mount);
//   eMc.yaml    tilt_from_camera as ViSP's hand-eye tools save eMc: a vpPoseVector (tx ty tz in
//               metres, theta-u in radians) in vpArray2D::saveYAML's layout.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "calibration/floor_calibration.h"
#include "calibration/mount_calibration.h"

namespace linetrack {

// One row of ANGLES.csv.
struct AnglesRow {
  std::string image;  // as written (a file name, or a path whose file name is matched)
  HeadAngles angles;  // radians
  int line = 0;
};

// Reads ANGLES.csv: the header `image,pan_deg,tilt_deg`, then one row per image (blank lines and
// lines starting with '#' skipped). Throws InputError naming the file and line for a missing
// file, a wrong header, a malformed or non-finite number, or an image listed twice.
std::vector<AnglesRow> ReadAnglesCsv(const std::string& path);

// The angles of the image at `image_path`, matched on its file name. Throws InputError naming the
// image and `csv_path` when ANGLES.csv has no row for it.
HeadAngles AnglesOfImage(const std::vector<AnglesRow>& rows, const std::string& image_path,
                         const std::string& csv_path);

// What mount.json says, as `live` and `replay` use it.
struct MountFile {
  Eigen::Isometry3d tilt_from_camera = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double rms_px = 0.0;
  std::optional<FloorGeometry> floor;  // present when a floor board was calibrated
};

// Reads mount.json. Throws InputError naming the file and the field for a missing file, bad
// JSON, a missing field, a matrix that is not a rigid transform, or non-finite numbers.
MountFile ReadMountFile(const std::string& path);

// The run mount.json describes, beside the calibration itself.
struct MountRunInfo {
  std::string camera_path;  // the intrinsics used
  PatternSpec pattern;
  std::optional<FloorCalibration> floor;  // with a floor board
  std::string floor_image;
  HeadAngles floor_angles;
  double board_thickness = 0.0;
};

// The text of mount.json for a successful calibration.
std::string MountJson(const MountCalibration& mount, const MountRunInfo& info);

// The text of eMc.yaml for tilt_from_camera.
std::string VispPoseYaml(const Eigen::Isometry3d& tilt_from_camera);

}  // namespace linetrack

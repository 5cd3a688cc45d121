// The files `linetrack calibrate-mount --out DIR` writes, built in memory first (then written
// all or nothing by WriteOutputFolder, output_files.h):
//   mount.json, eMc.yaml  (mount_file.h)
//   residuals.png         one panel per view: the image frame with each board corner's
//                         residual (detected minus predicted by the mount) magnified, its RMS,
//                         and the rejected views greyed with their reason
//   views/*.png, angles.csv  live runs only: the views grabbed and their angles, to re-run offline
#pragma once

#include <opencv2/core/mat.hpp>

#include <string>
#include <vector>

#include "calibration/mount_calibration.h"
#include "calibration/mount_file.h"
#include "calibration/output_files.h"

namespace linetrack {

// The picture of the residuals per view for images of width x height pixels.
std::string MountResidualsPng(const MountCalibration& mount, int width, int height);

// mount.json, eMc.yaml and residuals.png of a successful calibration.
OutputFiles MakeMountOutputs(const MountCalibration& mount, const MountRunInfo& info, int width,
                             int height);

// ANGLES.csv of named views (the inverse of ReadAnglesCsv).
std::string AnglesCsv(const std::vector<std::string>& images,
                      const std::vector<HeadAngles>& angles);

}  // namespace linetrack

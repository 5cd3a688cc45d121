// The files `linetrack calibrate --out DIR` writes, built in memory first so that the folder
// only appears when everything succeeded:
//   camera.xml        ViSP camera XML: perspectiveProjWithoutDistortion and WithDistortion
//   opencv.yml        OpenCV FileStorage: camera_matrix, distortion_coefficients (k1 k2 p1 p2 k3)
//   camera_info.yaml  ROS camera_info (plumb_bob = OpenCV's model)
//   report.json       per-view errors and fates, RMS, parameter standard deviations
//   coverage.png      every detected point over the image frame, coloured by view
//   overlays/*.png    each image with its detections and the reprojected board
#pragma once

#include <map>
#include <string>
#include <vector>

#include "calibration/calibrate.h"

namespace linetrack {

// Relative path in the output folder -> file content.
using OutputFiles = std::map<std::string, std::string>;

// Every output file of a successful calibration. `images` (same order as result.views) feed the
// overlays; without them no overlays are made. `camera_name` names the camera in XML and ROS.
OutputFiles MakeCalibrationOutputs(const CalibrationResult& result,
                                   const std::vector<CalibrationImage>& images,
                                   const CalibrationOptions& options,
                                   const std::string& camera_name);

// The text of each file (also used by MakeCalibrationOutputs).
std::string VispCameraXml(const CalibrationResult& result, const CalibrationOptions& options,
                          const std::string& camera_name);
std::string OpenCvYaml(const CalibrationResult& result, const CalibrationOptions& options);
std::string RosCameraInfoYaml(const CalibrationResult& result, const std::string& camera_name);
std::string ReportJson(const CalibrationResult& result, const CalibrationOptions& options);

// PNG pictures: the coverage of the image frame, and one view's overlay.
std::string CoveragePng(const CalibrationResult& result);
std::string OverlayPng(const CalibrationResult& result, const CalibrationOptions& options,
                       size_t view, const cv::Mat& gray);

// Writes the files into `dir` all or nothing: into a fresh sibling folder first, then renamed
// into place (moved file by file when `dir` already exists). Throws InputError naming the path
// when a file cannot be written; nothing is left behind then.
void WriteOutputFolder(const OutputFiles& files, const std::string& dir);

}  // namespace linetrack

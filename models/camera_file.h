// Cameras from the three files `linetrack calibrate` writes, recognised by their content: ViSP's
// camera XML, OpenCV's FileStorage (YAML or XML) and ROS's camera_info YAML. The OpenCV and ROS
// files hold the Brown-Conrady distortion (k1, k2, p1, p2, k3), which linetrack's cameras carry as
// ViSP's one-term radial model (models/camera.h), fitted over the image.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "models/camera.h"

namespace linetrack {

// Brown-Conrady distortion of normalised undistorted coordinates x = (X / Z, Y / Z), r^2 = |x|^2
// (OpenCV's calibrateCamera model, ROS's plumb_bob):
//   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + (2 p1 x y + p2 (r^2 + 2 x^2), p1 (r^2 + 2 y^2) + 2 p2
//   x y).
struct BrownConrady {
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;

  bool IsZero() const { return k1 == 0.0 && k2 == 0.0 && p1 == 0.0 && p2 == 0.0 && k3 == 0.0; }
  // x_d of x (the formula above).
  Eigen::Vector2d Distort(const Eigen::Vector2d& x) const;
  // x of x_d by fixed-point iteration (as cv::undistortPoints); nullopt when it does not converge
  // (far outside the region the coefficients were estimated on).
  std::optional<Eigen::Vector2d> Undistort(const Eigen::Vector2d& x_d) const;
};

// ViSP's one-term model (kud, kdu) standing for a Brown-Conrady distortion, fitted by linear least
// squares in pixels over a 41 x 41 grid of distorted pixels spanning the image ([0, 2 u0] x
// [0, 2 v0] without an image size), x the exact undistorted point of each grid point x_d:
//   kud minimises sum |P (x (1 + kud |x|^2) - x_d)|^2, kdu minimises sum |P (x_d (1 + kdu |x_d|^2)
//   - x)|^2, P = diag(px, py).
struct OneTermFit {
  double kud = 0.0, kdu = 0.0;
  double max_error_px = 0.0;  // largest |P (x (1 + kud |x|^2) - x_d)| over the grid (pixels)
};
OneTermFit FitOneTermDistortion(const CameraIntrinsics& pinhole, const BrownConrady& distortion);

// The formats a camera file can have.
enum class CameraFileFormat { kVispXml, kOpenCv, kRosCameraInfo };
const char* ToString(CameraFileFormat format);

// A camera as read from a file, with what its format held beside linetrack's model.
struct CameraFile {
  CameraIntrinsics camera;
  CameraFileFormat format = CameraFileFormat::kVispXml;
  BrownConrady brown_conrady;     // the file's distortion (OpenCV, ROS); zero for ViSP files
  double approximation_px = 0.0;  // OneTermFit::max_error_px of the camera's kud (0 when exact)
};

// Reads a camera from a ViSP camera XML (ReadCameraXml), an OpenCV FileStorage file
// (camera_matrix, distortion_coefficients, optional image_width and image_height) or a ROS
// camera_info YAML (camera_matrix, distortion_model plumb_bob, distortion_coefficients,
// image_width, image_height, camera_name). `name`: the camera's name (ViSP, ROS; OpenCV files
// hold one unnamed camera); `width`/`height` 0: any size. Throws InputError naming the file.
CameraFile ReadCameraFile(const std::string& path, const std::string& name = "", int width = 0,
                          int height = 0);

// ReadCameraFile(...).camera: the camera of any of the three formats.
CameraIntrinsics ReadCamera(const std::string& path, const std::string& name = "", int width = 0,
                            int height = 0);

// The parsers of the OpenCV and ROS formats, on the file's text (`path` names it in errors).
CameraFile ParseOpenCvCamera(const std::string& text, const std::string& path);
CameraFile ParseRosCameraInfo(const std::string& text, const std::string& path);

}  // namespace linetrack

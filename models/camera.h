// Pinhole camera intrinsics with ViSP's radial distortion model (vpCameraParameters):
//   undistorted -> distorted: u = u0 + px x (1 + kud r^2), v = v0 + py y (1 + kud r^2),
//                             r^2 = x^2 + y^2 (normalised undistorted coordinates);
//   distorted -> undistorted: x = (u - u0)(1 + kdu r'^2) / px, r'^2 from the distorted pixel.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

namespace linetrack {

struct CameraIntrinsics {
  std::string name = "Camera";
  int width = 0;  // image size in pixels; 0 when the file does not say
  int height = 0;
  double px = 0.0, py = 0.0;  // focal lengths in pixels
  double u0 = 0.0, v0 = 0.0;  // principal point (u = column, v = row)
  bool has_distortion = false;
  double kud = 0.0;  // undistorted -> distorted
  double kdu = 0.0;  // distorted -> undistorted

  // Finite, positive focal lengths, finite centre; size positive when given.
  bool Check(std::string* why) const;

  // The same camera without distortion (the model of an undistorted image).
  CameraIntrinsics Undistorted() const;

  // Pixel of a camera-frame point (z > 0) in the undistorted image.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_cam) const {
    return {u0 + px * point_cam.x() / point_cam.z(), v0 + py * point_cam.y() / point_cam.z()};
  }

  // Ray (x, y, 1) through an undistorted pixel.
  Eigen::Vector3d Ray(const Eigen::Vector2d& uv) const {
    return {(uv.x() - u0) / px, (uv.y() - v0) / py, 1.0};
  }

  // Undistorted pixel -> distorted pixel and back, with kud and kdu (identity without distortion).
  Eigen::Vector2d Distort(const Eigen::Vector2d& uv) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& uv) const;

  // True when the pixel lies inside the image [0, width) x [0, height).
  bool Contains(const Eigen::Vector2d& uv) const {
    return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() < width && uv.y() < height;
  }
};

// The distorted pixel q with camera.Undistort(q) = uv: the exact inverse of the kdu model
// (x_u = x_d (1 + kdu r_d^2) in normalised coordinates), solved radially by Newton's method.
// This is what the renderer draws (output pixel q shows undistorted pixel Undistort(q)); ViSP's
// kud model is only an approximate inverse. Identity without distortion.
Eigen::Vector2d DistortedPixelOf(const CameraIntrinsics& camera, const Eigen::Vector2d& uv);

// The text of a camera file. Throws InputError naming the file when it is missing or unreadable.
std::string ReadCameraText(const std::string& path);

// Reads a camera from a ViSP camera XML file (vpXmlParserCamera); ReadCamera
// (models/camera_file.h) reads OpenCV and ROS files too. The model with distortion is
// taken when the file has one, else the model without. `name` empty: the first camera.
// `width`/`height` 0: any size. Throws InputError naming the file and what is missing.
CameraIntrinsics ReadCameraXml(const std::string& path, const std::string& name = "", int width = 0,
                               int height = 0);

// Writes a fresh ViSP camera XML file holding `camera` (both projection models when it has
// distortion: the undistorted one then repeats px, py, u0, v0). Replaces an existing file.
// `additional_info` is an XML fragment stored in <additional_information>.
void WriteCameraXml(const std::string& path, const CameraIntrinsics& camera,
                    const std::string& additional_info = "");

// Writes a fresh file with the two models ViSP's calibration produces for one camera: `plain`
// (perspectiveProjWithoutDistortion) and, when given, `distorted` (perspectiveProjWithDistortion).
void WriteCameraXml(const std::string& path, const CameraIntrinsics& plain,
                    const std::optional<CameraIntrinsics>& distorted,
                    const std::string& additional_info);

}  // namespace linetrack

#include "models/camera_file.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

#include "models/errors.h"

namespace linetrack {
namespace {

constexpr int kFitGrid = 40;  // grid cells per image side of FitOneTermDistortion

// The intrinsics of a 3x3 pinhole matrix K = [fx 0 cx; 0 fy cy; 0 0 1] (row-major `k`).
CameraIntrinsics FromCameraMatrix(const std::vector<double>& k, const std::string& path,
                                  const std::string& field) {
  if (k.size() != 9) {
    throw InputError(Located(
        path, 0, field + ": expected 9 numbers (a 3x3 matrix), got " + std::to_string(k.size())));
  }
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    throw InputError(Located(path, 0, field + ": not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]"));
  }
  CameraIntrinsics camera;
  camera.px = k[0];
  camera.u0 = k[2];
  camera.py = k[4];
  camera.v0 = k[5];
  return camera;
}

// Brown-Conrady coefficients k1 k2 p1 p2 [k3 [more]]: 4 or 5, or more when the rest are zero.
BrownConrady FromCoefficients(const std::vector<double>& d, const std::string& path,
                              const std::string& field) {
  BrownConrady b;
  if (d.empty()) return b;
  if (d.size() < 4) {
    throw InputError(Located(
        path, 0,
        field + ": expected k1 k2 p1 p2 [k3], got " + std::to_string(d.size()) + " numbers"));
  }
  for (size_t i = 5; i < d.size(); ++i) {
    if (d[i] != 0.0) {
      throw InputError(Located(path, 0,
                               field + ": only k1 k2 p1 p2 k3 are supported (coefficient " +
                                   std::to_string(i + 1) + " is not zero)"));
    }
  }
  b.k1 = d[0];
  b.k2 = d[1];
  b.p1 = d[2];
  b.p2 = d[3];
  b.k3 = d.size() > 4 ? d[4] : 0.0;
  return b;
}

// The camera of a pinhole matrix and a Brown-Conrady distortion, with ViSP's one-term model
// fitted when there is distortion.
CameraFile MakeCameraFile(CameraIntrinsics camera, const BrownConrady& distortion,
                          CameraFileFormat format, const std::string& path) {
  std::string why;
  if (!camera.Check(&why)) throw InputError(Located(path, 0, why));
  CameraFile file;
  file.format = format;
  file.brown_conrady = distortion;
  if (!distortion.IsZero()) {
    const OneTermFit fit = FitOneTermDistortion(camera, distortion);
    if (!std::isfinite(fit.max_error_px)) {
      throw InputError(Located(path, 0,
                               "the distortion coefficients cannot be inverted over the "
                               "image (not a camera model)"));
    }
    camera.has_distortion = true;
    camera.kud = fit.kud;
    camera.kdu = fit.kdu;
    file.approximation_px = fit.max_error_px;
  }
  file.camera = camera;
  return file;
}

// The values of an OpenCV matrix node (rows, cols, data), row-major. Its size is checked before
// anything is read: cv::read allocates rows x cols as written, however large.
std::vector<double> MatValues(const cv::FileNode& node, const std::string& path,
                              const std::string& field) {
  std::vector<double> values;
  if (node.empty() || node.isNone()) return values;
  constexpr int kMaxSide = 16;
  const bool shaped =
      node.isMap() && node["rows"].isInt() && node["cols"].isInt() && node["data"].isSeq();
  if (!shaped) throw InputError(Located(path, 0, field + ": expected rows, cols and a data list"));
  const int rows = static_cast<int>(node["rows"]);
  const int cols = static_cast<int>(node["cols"]);
  const cv::FileNode data = node["data"];
  if (rows < 1 || cols < 1 || rows > kMaxSide || cols > kMaxSide ||
      static_cast<size_t>(rows) * static_cast<size_t>(cols) != data.size()) {
    throw InputError(Located(path, 0,
                             field + ": " + std::to_string(rows) + " x " + std::to_string(cols) +
                                 " does not match its " + std::to_string(data.size()) + " values"));
  }
  for (const cv::FileNode& v : data) {
    if (!v.isInt() && !v.isReal()) {
      throw InputError(Located(path, 0, field + ": data holds a value that is not a number"));
    }
    values.push_back(static_cast<double>(v));
  }
  return values;
}

std::vector<double> YamlNumbers(const YAML::Node& matrix, const std::string& path,
                                const std::string& field) {
  if (!matrix || !matrix.IsMap() || !matrix["data"] || !matrix["data"].IsSequence()) {
    throw InputError(Located(path, 0, field + ": expected rows, cols and a data list"));
  }
  std::vector<double> values;
  for (const YAML::Node& v : matrix["data"]) {
    try {
      values.push_back(v.as<double>());
    } catch (const YAML::Exception&) {
      throw InputError(Located(path, 0, field + ": data holds a value that is not a number"));
    }
  }
  return values;
}

int YamlInt(const YAML::Node& root, const char* key, const std::string& path) {
  if (!root[key]) return 0;
  try {
    return root[key].as<int>();
  } catch (const YAML::Exception&) {
    throw InputError(Located(path, 0, std::string(key) + ": not an integer"));
  }
}

}  // namespace

Eigen::Vector2d BrownConrady::Distort(const Eigen::Vector2d& x) const {
  const double r2 = x.squaredNorm();
  const double radial = 1.0 + ((k3 * r2 + k2) * r2 + k1) * r2;
  const double xy = x.x() * x.y();
  return {x.x() * radial + 2.0 * p1 * xy + p2 * (r2 + 2.0 * x.x() * x.x()),
          x.y() * radial + p1 * (r2 + 2.0 * x.y() * x.y()) + 2.0 * p2 * xy};
}

std::optional<Eigen::Vector2d> BrownConrady::Undistort(const Eigen::Vector2d& x_d) const {
  constexpr int kIterations = 100;
  constexpr double kTolerance = 1e-12;
  Eigen::Vector2d x = x_d;
  for (int i = 0; i < kIterations; ++i) {
    const double r2 = x.squaredNorm();
    const double radial = 1.0 + ((k3 * r2 + k2) * r2 + k1) * r2;
    if (!(radial > 0.0)) return std::nullopt;
    const double xy = x.x() * x.y();
    const Eigen::Vector2d tangential(2.0 * p1 * xy + p2 * (r2 + 2.0 * x.x() * x.x()),
                                     p1 * (r2 + 2.0 * x.y() * x.y()) + 2.0 * p2 * xy);
    x = (x_d - tangential) / radial;
  }
  if (!x.allFinite() || (Distort(x) - x_d).norm() > kTolerance) return std::nullopt;
  return x;
}

OneTermFit FitOneTermDistortion(const CameraIntrinsics& pinhole, const BrownConrady& distortion) {
  const double width = pinhole.width > 0 ? pinhole.width : 2.0 * pinhole.u0;
  const double height = pinhole.height > 0 ? pinhole.height : 2.0 * pinhole.v0;
  const Eigen::Vector2d p(pinhole.px, pinhole.py);
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> samples;  // (x, x_d)
  for (int a = 0; a <= kFitGrid; ++a) {
    for (int b = 0; b <= kFitGrid; ++b) {
      const Eigen::Vector2d d((width * a / kFitGrid - pinhole.u0) / pinhole.px,
                              (height * b / kFitGrid - pinhole.v0) / pinhole.py);
      if (const std::optional<Eigen::Vector2d> x = distortion.Undistort(d)) {
        samples.emplace_back(*x, d);
      }
    }
  }
  OneTermFit fit;
  if (samples.empty()) {
    fit.max_error_px = std::numeric_limits<double>::infinity();
    return fit;
  }
  // Each fit is linear in its coefficient k: residual P (a + k r^2 a - b) over (a, b) = (x, x_d)
  // for kud and (x_d, x) for kdu, so k = sum (r^2 P a) . P (b - a) / sum |r^2 P a|^2.
  auto fit_coefficient = [&](bool forward) {
    double numerator = 0.0, denominator = 0.0;
    for (const auto& [x, d] : samples) {
      const Eigen::Vector2d& a = forward ? x : d;
      const Eigen::Vector2d& b = forward ? d : x;
      const Eigen::Vector2d basis = a.squaredNorm() * p.cwiseProduct(a);
      numerator += basis.dot(p.cwiseProduct(b - a));
      denominator += basis.squaredNorm();
    }
    return denominator > 0.0 ? numerator / denominator : 0.0;
  };
  fit.kud = fit_coefficient(true);
  fit.kdu = fit_coefficient(false);
  for (const auto& [x, d] : samples) {
    const Eigen::Vector2d one_term = x * (1.0 + fit.kud * x.squaredNorm());
    fit.max_error_px = std::max(fit.max_error_px, p.cwiseProduct(one_term - d).norm());
  }
  return fit;
}

const char* ToString(CameraFileFormat format) {
  switch (format) {
    case CameraFileFormat::kVispXml:
      return "ViSP camera XML";
    case CameraFileFormat::kOpenCv:
      return "OpenCV calibration";
    case CameraFileFormat::kRosCameraInfo:
      return "ROS camera_info";
  }
  return "?";
}

CameraFile ParseOpenCvCamera(const std::string& text, const std::string& path) {
  cv::FileStorage storage;
  try {
    storage.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  } catch (const cv::Exception& e) {
    throw InputError(Located(path, 0, "malformed OpenCV file: " + e.msg));
  } catch (const std::exception& e) {  // OpenCV's parser passes on std::length_error and others
    throw InputError(Located(path, 0, std::string("malformed OpenCV file: ") + e.what()));
  }
  if (!storage.isOpened()) throw InputError(Located(path, 0, "malformed OpenCV file"));
  try {
    const cv::FileNode k = storage["camera_matrix"];
    if (k.empty()) throw InputError(Located(path, 0, "no camera_matrix in this OpenCV file"));
    CameraIntrinsics camera =
        FromCameraMatrix(MatValues(k, path, "camera_matrix"), path, "camera_matrix");
    if (!storage["image_width"].empty()) camera.width = static_cast<int>(storage["image_width"]);
    if (!storage["image_height"].empty()) camera.height = static_cast<int>(storage["image_height"]);
    const BrownConrady distortion = FromCoefficients(
        MatValues(storage["distortion_coefficients"], path, "distortion_coefficients"), path,
        "distortion_coefficients");
    return MakeCameraFile(camera, distortion, CameraFileFormat::kOpenCv, path);
  } catch (const InputError&) {
    throw;
  } catch (const cv::Exception& e) {
    throw InputError(Located(path, 0, "malformed OpenCV file: " + e.msg));
  } catch (const std::exception& e) {
    throw InputError(Located(path, 0, std::string("malformed OpenCV file: ") + e.what()));
  }
}

CameraFile ParseRosCameraInfo(const std::string& text, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(Located(path, e.mark.line + 1, "malformed YAML: " + e.msg));
  }
  if (!root.IsMap() || !root["camera_matrix"]) {
    throw InputError(Located(path, 0, "no camera_matrix in this camera_info file"));
  }
  CameraIntrinsics camera = FromCameraMatrix(
      YamlNumbers(root["camera_matrix"], path, "camera_matrix"), path, "camera_matrix");
  camera.width = YamlInt(root, "image_width", path);
  camera.height = YamlInt(root, "image_height", path);
  if (root["camera_name"] && root["camera_name"].IsScalar()) {
    camera.name = root["camera_name"].as<std::string>();
  }
  const std::string model = root["distortion_model"] && root["distortion_model"].IsScalar()
                                ? root["distortion_model"].as<std::string>()
                                : "plumb_bob";
  BrownConrady distortion;
  if (root["distortion_coefficients"]) {
    const std::vector<double> d =
        YamlNumbers(root["distortion_coefficients"], path, "distortion_coefficients");
    if (model != "plumb_bob" &&
        !(d.empty() || std::all_of(d.begin(), d.end(), [](double v) { return v == 0.0; }))) {
      throw InputError(
          Located(path, 0, "distortion_model '" + model + "' is not supported (plumb_bob only)"));
    }
    distortion = FromCoefficients(d, path, "distortion_coefficients");
  }
  return MakeCameraFile(camera, distortion, CameraFileFormat::kRosCameraInfo, path);
}

CameraFile ReadCameraFile(const std::string& path, const std::string& name, int width, int height) {
  const std::string text = ReadCameraText(path);
  const size_t first = text.find_first_not_of(" \t\r\n");
  const bool opencv = text.find("<opencv_storage>") != std::string::npos ||
                      text.compare(first == std::string::npos ? 0 : first, 6, "%YAML:") == 0 ||
                      text.find("!!opencv-matrix") != std::string::npos;
  CameraFile file;
  if (opencv) {
    file = ParseOpenCvCamera(text, path);
    if (!name.empty()) {
      throw InputError(Located(path, 0,
                               "an OpenCV calibration file holds one unnamed camera: no "
                               "camera named '" +
                                   name + "'"));
    }
  } else if (first != std::string::npos && text[first] == '<') {
    file.camera = ReadCameraXml(path, name, width, height);
    return file;
  } else if (text.find("camera_matrix") != std::string::npos) {
    file = ParseRosCameraInfo(text, path);
    if (!name.empty() && name != file.camera.name) {
      throw InputError(Located(
          path, 0,
          "no camera named '" + name + "' in this file (it holds '" + file.camera.name + "')"));
    }
  } else {
    throw InputError(Located(path, 0,
                             "not a camera file: expected a ViSP camera XML, an OpenCV "
                             "calibration file or a ROS camera_info YAML"));
  }
  if (width > 0 && file.camera.width > 0 &&
      (file.camera.width != width || file.camera.height != height)) {
    throw InputError(Located(path, 0,
                             "no camera of size " + std::to_string(width) + "x" +
                                 std::to_string(height) + " in this file"));
  }
  return file;
}

CameraIntrinsics ReadCamera(const std::string& path, const std::string& name, int width,
                            int height) {
  return ReadCameraFile(path, name, width, height).camera;
}

}  // namespace linetrack

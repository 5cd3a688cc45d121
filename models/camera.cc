#include "models/camera.h"
#include "models/silence_stdout.h"

#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpXmlParserCamera.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "models/errors.h"

namespace linetrack {
std::string ReadCameraText(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(Located(path, 0, "no such camera file"));
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || !std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "cannot read the camera file"));
  }
  // A NUL byte means a binary file; OpenCV's FileStorage parser also dereferences null on some.
  std::string contents = text.str();
  const size_t nul = contents.find('\0');
  if (nul != std::string::npos) {
    throw InputError(
        Located(path, 0, "not a text file (a NUL byte at offset " + std::to_string(nul) + ")"));
  }
  return contents;
}

namespace {

// Text of the first <tag>...</tag> inside `xml` (trimmed), or nullopt.
std::optional<std::string> FirstElement(const std::string& xml, const std::string& tag) {
  const std::string open = "<" + tag + ">", close = "</" + tag + ">";
  const size_t begin = xml.find(open);
  if (begin == std::string::npos) return std::nullopt;
  const size_t start = begin + open.size();
  const size_t end = xml.find(close, start);
  if (end == std::string::npos) return std::nullopt;
  const std::string text = xml.substr(start, end - start);
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return std::string();
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

// Tracker settings files (<conf><camera><px>..</px>...) also carry intrinsics (ViSP samples).
std::optional<CameraIntrinsics> ReadTrackerConfCamera(const std::string& path,
                                                      const std::string& xml) {
  const size_t begin = xml.find("<camera>");
  const size_t end = xml.find("</camera>");
  if (xml.find("<conf>") == std::string::npos || begin == std::string::npos || end < begin) {
    return std::nullopt;
  }
  const std::string block = xml.substr(begin, end - begin);
  CameraIntrinsics cam;
  double* fields[] = {&cam.px, &cam.py, &cam.u0, &cam.v0};
  const char* names[] = {"px", "py", "u0", "v0"};
  for (int i = 0; i < 4; ++i) {
    const std::optional<std::string> value = FirstElement(block, names[i]);
    if (!value)
      throw InputError(Located(path, 0, std::string("<camera> has no <") + names[i] + ">"));
    try {
      size_t used = 0;
      *fields[i] = std::stod(*value, &used);
      if (used != value->size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw InputError(
          Located(path, 0, std::string("<") + names[i] + "> is not a number: '" + *value + "'"));
    }
  }
  return cam;
}

CameraIntrinsics FromVisp(const vpCameraParameters& p) {
  CameraIntrinsics cam;
  cam.px = p.get_px();
  cam.py = p.get_py();
  cam.u0 = p.get_u0();
  cam.v0 = p.get_v0();
  cam.has_distortion = p.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion;
  cam.kud = cam.has_distortion ? p.get_kud() : 0.0;
  cam.kdu = cam.has_distortion ? p.get_kdu() : 0.0;
  return cam;
}

}  // namespace

bool CameraIntrinsics::Check(std::string* why) const {
  const bool finite = std::isfinite(px) && std::isfinite(py) && std::isfinite(u0) &&
                      std::isfinite(v0) && std::isfinite(kud) && std::isfinite(kdu);
  if (!finite) {
    *why = "intrinsics are not finite numbers";
    return false;
  }
  if (px <= 0.0 || py <= 0.0) {
    *why = "focal lengths px, py must be positive";
    return false;
  }
  if (width < 0 || height < 0 || (width == 0) != (height == 0)) {
    *why = "image size must be both positive or both unknown";
    return false;
  }
  return true;
}

CameraIntrinsics CameraIntrinsics::Undistorted() const {
  CameraIntrinsics cam = *this;
  cam.has_distortion = false;
  cam.kud = cam.kdu = 0.0;
  return cam;
}

Eigen::Vector2d CameraIntrinsics::Distort(const Eigen::Vector2d& uv) const {
  if (!has_distortion) return uv;
  const double x = (uv.x() - u0) / px, y = (uv.y() - v0) / py;
  const double k = 1.0 + kud * (x * x + y * y);
  return {u0 + px * x * k, v0 + py * y * k};
}

Eigen::Vector2d CameraIntrinsics::Undistort(const Eigen::Vector2d& uv) const {
  if (!has_distortion) return uv;
  const double x = (uv.x() - u0) / px, y = (uv.y() - v0) / py;
  const double k = 1.0 + kdu * (x * x + y * y);
  return {u0 + px * x * k, v0 + py * y * k};
}

Eigen::Vector2d DistortedPixelOf(const CameraIntrinsics& camera, const Eigen::Vector2d& uv) {
  if (!camera.has_distortion || camera.kdu == 0.0) return uv;
  const double x = (uv.x() - camera.u0) / camera.px, y = (uv.y() - camera.v0) / camera.py;
  const double rho_u = std::hypot(x, y);
  if (rho_u == 0.0) return uv;
  // Solve rho_d (1 + kdu rho_d^2) = rho_u; increasing in rho_d while 1 + 3 kdu rho_d^2 > 0.
  double rho = rho_u;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const double f = rho * (1.0 + camera.kdu * rho * rho) - rho_u;
    const double slope = 1.0 + 3.0 * camera.kdu * rho * rho;
    if (slope <= 1e-6) break;
    const double step = f / slope;
    rho -= step;
    if (std::abs(step) < 1e-13) break;
  }
  const double scale = rho / rho_u;
  return {camera.u0 + camera.px * x * scale, camera.v0 + camera.py * y * scale};
}

CameraIntrinsics ReadCameraXml(const std::string& path, const std::string& name, int width,
                               int height) {
  const std::string xml = ReadCameraText(path);
  CameraIntrinsics cam;
  if (xml.find("<camera>") == std::string::npos) {
    throw InputError(Located(path, 0, "not a ViSP camera file: no <camera> element"));
  }
  std::string camera_name = name;
  if (camera_name.empty()) camera_name = FirstElement(xml, "name").value_or("");
  bool found = false;
  if (!camera_name.empty()) {
    vpXmlParserCamera parser;
    vpCameraParameters params;
    ScopedStdoutSilencer quiet;
    for (auto model : {vpCameraParameters::perspectiveProjWithDistortion,
                       vpCameraParameters::perspectiveProjWithoutDistortion}) {
      try {
        if (parser.parse(params, path, camera_name, model, width, height) ==
            vpXmlParserCamera::SEQUENCE_OK) {
          cam = FromVisp(params);
          cam.name = camera_name;
          cam.width = static_cast<int>(parser.getWidth());
          cam.height = static_cast<int>(parser.getHeight());
          found = true;
          break;
        }
      } catch (const vpException& e) {
        throw InputError(Located(path, 0, std::string("malformed camera XML: ") + e.getMessage()));
      }
    }
  }
  if (!found && name.empty()) {
    if (std::optional<CameraIntrinsics> conf = ReadTrackerConfCamera(path, xml)) {
      cam = *conf;
      found = true;
    }
  }
  if (!found) {
    std::string what = "no camera";
    if (!name.empty()) what += " named '" + name + "'";
    if (width > 0) what += " of size " + std::to_string(width) + "x" + std::to_string(height);
    throw InputError(Located(path, 0, what + " in this file"));
  }
  std::string why;
  if (!cam.Check(&why)) throw InputError(Located(path, 0, why));
  return cam;
}

void WriteCameraXml(const std::string& path, const CameraIntrinsics& camera,
                    const std::string& additional_info) {
  WriteCameraXml(path, camera.Undistorted(),
                 camera.has_distortion ? std::optional<CameraIntrinsics>(camera) : std::nullopt,
                 additional_info);
}

void WriteCameraXml(const std::string& path, const CameraIntrinsics& plain,
                    const std::optional<CameraIntrinsics>& distorted,
                    const std::string& additional_info) {
  std::error_code ec;
  std::filesystem::remove(path, ec);  // save() would silently keep an existing camera
  vpXmlParserCamera parser;
  const unsigned w = static_cast<unsigned>(plain.width), h = static_cast<unsigned>(plain.height);
  ScopedStdoutSilencer quiet;
  int status = parser.save(vpCameraParameters(plain.px, plain.py, plain.u0, plain.v0), path,
                           plain.name, w, h, additional_info);
  if (status == vpXmlParserCamera::SEQUENCE_OK && distorted) {
    const vpCameraParameters model(distorted->px, distorted->py, distorted->u0, distorted->v0,
                                   distorted->kud, distorted->kdu);
    status = parser.save(model, path, plain.name, w, h);
  }
  if (status != vpXmlParserCamera::SEQUENCE_OK) {
    throw InputError(Located(path, 0, "cannot write the camera file"));
  }
}

}  // namespace linetrack

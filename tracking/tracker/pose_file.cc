#include "tracking/tracker/pose_file.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "models/errors.h"

namespace linetrack {

Eigen::Isometry3d CamFromWorldFromPoseVector(const Eigen::Matrix<double, 6, 1>& pose_vector) {
  const Eigen::Vector3d tu = pose_vector.tail<3>();
  const double theta = tu.norm();
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  if (theta > 0.0) {
    cam_from_world.linear() = Eigen::AngleAxisd(theta, tu / theta).toRotationMatrix();
  }
  cam_from_world.translation() = pose_vector.head<3>();
  return cam_from_world;
}

Eigen::Isometry3d ParsePoseText(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size() || !std::isfinite(value)) {
      throw InputError(Located(path, 0, "pose: '" + token + "' is not a finite number"));
    }
    values.push_back(value);
  }
  if (values.size() == 6) {
    return CamFromWorldFromPoseVector(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(values.data()));
  }
  if (values.size() != 16) {
    throw InputError(Located(path, 0,
                             "pose: expected 6 numbers (tx ty tz tux tuy tuz) or 16 (a 4x4 "
                             "matrix), found " +
                                 std::to_string(values.size())));
  }
  const Eigen::Matrix4d m =
      Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data());
  if (m.row(3).transpose() != Eigen::Vector4d(0, 0, 0, 1)) {
    throw InputError(Located(path, 0, "pose: the last row of the 4x4 matrix must be 0 0 0 1"));
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-4 || r.determinant() < 0.0) {
    throw InputError(Located(path, 0, "pose: the 3x3 block is not a rotation"));
  }
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  cam_from_world.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  cam_from_world.translation() = m.topRightCorner<3, 1>();
  return cam_from_world;
}

Eigen::Isometry3d ReadPoseFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(Located(path, 0, "cannot read the pose file"));
  std::stringstream text;
  text << in.rdbuf();
  return ParsePoseText(text.str(), path);
}

}  // namespace linetrack

#include "tracking/head/head_kinematics.h"

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/robot/vpBiclops.h>
#include <visp3/robot/vpPtu46.h>

#include "models/pan_tilt.h"

namespace linetrack {

bool ParseHeadModel(const std::string& name, HeadModel* model) {
  if (name == "ptu46") {
    *model = HeadModel::kPtu46;
    return true;
  }
  if (name == "biclops") {
    *model = HeadModel::kBiclops;
    return true;
  }
  return false;
}

Eigen::Isometry3d AlignedMount(const Eigen::Vector3d& centre, CameraRoll roll) {
  // Camera axes in the tilt frame: x right = -y_tilt, y down = -z_tilt, z forward = x_tilt.
  const double sign = roll == CameraRoll::kUpright ? 1.0 : -1.0;
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear().col(0) = Eigen::Vector3d(0.0, -sign, 0.0);
  mount.linear().col(1) = Eigen::Vector3d(0.0, 0.0, -sign);
  mount.linear().col(2) = Eigen::Vector3d(1.0, 0.0, 0.0);
  mount.translation() = centre;
  return mount;
}

namespace {

constexpr double kRotationTolerance = 1e-6;  // |R^T R - I| and |det R - 1|
constexpr double kMaxMountOffset = 1.0;      // metres from the axes' crossing

bool IsRotation(const Eigen::Matrix3d& r) {
  return r.allFinite() &&
         (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < kRotationTolerance &&
         std::abs(r.determinant() - 1.0) < kRotationTolerance;
}

}  // namespace

bool HeadGeometry::Check(std::string* why) const {
  if (!IsRotation(tilt_from_camera.linear()) || !tilt_from_camera.translation().allFinite()) {
    *why = "the camera mount must be a rigid transform (finite, orthonormal rotation)";
    return false;
  }
  if (!(tilt_from_camera.translation().norm() <= kMaxMountOffset)) {
    *why = "the camera must sit within 1 m of the head's axes";
    return false;
  }
  if (!IsRotation(level_from_base)) {
    *why = "the head base's tilt must be a rotation";
    return false;
  }
  return true;
}

HeadGeometry GeometryOf(HeadModel model) {
  HeadGeometry g;
  if (model == HeadModel::kPtu46) {
    g.tilt_from_camera = AlignedMount(Eigen::Vector3d(0.0, vpPtu46::L, vpPtu46::h),  //
                                      CameraRoll::kUpright);
  } else {
    g.tilt_from_camera =
        AlignedMount(Eigen::Vector3d(0.0, 0.0, -static_cast<double>(vpBiclops::h)),  //
                     CameraRoll::kUpsideDown);
  }
  return g;
}

Eigen::Isometry3d BaseFromCamera(const HeadGeometry& geometry, double pan, double tilt) {
  Eigen::Isometry3d base_from_tilt = Eigen::Isometry3d::Identity();
  base_from_tilt.linear() = BaseFromTiltRotation(pan, tilt);
  return base_from_tilt * geometry.tilt_from_camera;
}

HeadServoMatrices ServoMatricesOf(const HeadGeometry& geometry, double tilt) {
  HeadServoMatrices m;
  const Eigen::Isometry3d camera_from_tilt = geometry.tilt_from_camera.inverse();
  vpHomogeneousMatrix cMe;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c)
      cMe[r][c] = camera_from_tilt.linear()(r, c);
    cMe[r][3] = camera_from_tilt.translation()(r);
  }
  m.cVe.buildFrom(cMe);
  // The pan axis (base z) seen from the tilt frame: Ry(tilt)^T z = (-sin tilt, 0, cos tilt).
  m.eJe.resize(6, 2);  // zeroed
  m.eJe[3][0] = -std::sin(tilt);
  m.eJe[5][0] = std::cos(tilt);
  m.eJe[4][1] = 1.0;
  return m;
}

Eigen::Matrix<double, 6, 2> CameraJacobian(const HeadGeometry& geometry, double tilt) {
  const HeadServoMatrices m = ServoMatricesOf(geometry, tilt);
  const vpMatrix J = static_cast<vpMatrix>(m.cVe) * m.eJe;
  Eigen::Matrix<double, 6, 2> out;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 2; ++c)
      out(r, c) = J[r][c];
  return out;
}

}  // namespace linetrack

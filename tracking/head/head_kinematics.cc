#include "tracking/head/head_kinematics.h"

#include <visp3/robot/vpBiclops.h>
#include <visp3/robot/vpPtu46.h>

namespace linetrack {
namespace {

// ViSP's joint vector q = (pan, sign * tilt): vpPtu46 counts tilt upwards, vpBiclops (DH1)
// downwards like the project.
double ViSPTiltSign(HeadModel model) {
  return model == HeadModel::kPtu46 ? -1.0 : 1.0;
}

vpColVector ViSPJoints(HeadModel model, double pan, double tilt) {
  vpColVector q(2);
  q[0] = pan;
  q[1] = ViSPTiltSign(model) * tilt;
  return q;
}

}  // namespace

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

HeadGeometry GeometryOf(HeadModel model) {
  HeadGeometry g;
  if (model == HeadModel::kPtu46) {
    g.camera_offset = Eigen::Vector3d(0.0, vpPtu46::L, vpPtu46::h);
  } else {
    g.camera_offset = Eigen::Vector3d(0.0, 0.0, -static_cast<double>(vpBiclops::h));
    g.camera_upside_down = true;
  }
  return g;
}

Eigen::Isometry3d BaseFromCamera(const HeadGeometry& geometry, double pan, double tilt) {
  // Camera axes in the tilt frame: x right = -y_tilt, y down = -z_tilt, z forward = x_tilt.
  Eigen::Matrix3d tilt_from_camera;
  tilt_from_camera.col(0) = Eigen::Vector3d(0.0, -1.0, 0.0);
  tilt_from_camera.col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);
  tilt_from_camera.col(2) = Eigen::Vector3d(1.0, 0.0, 0.0);
  if (geometry.camera_upside_down) {
    tilt_from_camera.col(0) *= -1.0;
    tilt_from_camera.col(1) *= -1.0;
  }
  // Ry(tilt) with positive tilt looking down: rotation about +y by +tilt sends x to
  // (cos, 0, -sin).
  const Eigen::Matrix3d base_from_tilt = (Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()) *
                                          Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()))
                                             .toRotationMatrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = base_from_tilt * tilt_from_camera;
  pose.translation() = base_from_tilt * geometry.camera_offset;
  return pose;
}

HeadServoMatrices ServoMatricesOf(HeadModel model, double pan, double tilt) {
  HeadServoMatrices m;
  vpMatrix eJe_visp;
  const vpColVector q = ViSPJoints(model, pan, tilt);
  if (model == HeadModel::kPtu46) {
    const vpPtu46 ptu;
    ptu.get_eJe(q, eJe_visp);
    ptu.get_cVe(m.cVe);
  } else {
    const vpBiclops biclops;
    biclops.get_eJe(q, eJe_visp);
    biclops.get_cVe(m.cVe);
  }
  // d q_visp / d q_ours = diag(1, tilt sign).
  m.eJe = eJe_visp;
  const double s = ViSPTiltSign(model);
  for (unsigned r = 0; r < 6; ++r)
    m.eJe[r][1] = s * eJe_visp[r][1];
  return m;
}

Eigen::Matrix<double, 6, 2> CameraJacobian(HeadModel model, double pan, double tilt) {
  const HeadServoMatrices m = ServoMatricesOf(model, pan, tilt);
  const vpMatrix J = static_cast<vpMatrix>(m.cVe) * m.eJe;
  Eigen::Matrix<double, 6, 2> out;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 2; ++c)
      out(r, c) = J[r][c];
  return out;
}

}  // namespace linetrack

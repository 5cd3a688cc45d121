#include "calibration/pose_least_squares.h"

#include <Eigen/Dense>
#include <cmath>

#include "models/pan_tilt.h"

namespace linetrack {
namespace {

constexpr double kMaxDamping = 1e12;
constexpr double kMinStep = 1e-12;        // metres or radians: a smaller step has converged
constexpr double kSingularRatio = 1e-12;  // smallest / largest eigenvalue of J^T J

std::vector<Eigen::Isometry3d> Moved(const std::vector<Eigen::Isometry3d>& poses,
                                     const Eigen::VectorXd& delta) {
  std::vector<Eigen::Isometry3d> moved = poses;
  for (size_t k = 0; k < poses.size(); ++k)
    moved[k] = MovedPose(poses[k], delta.segment<6>(6 * static_cast<Eigen::Index>(k)));
  return moved;
}

}  // namespace

Eigen::Matrix3d SkewMatrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Vector2d ProjectPoint(const CameraIntrinsics& camera, const Eigen::Vector3d& p,
                             Eigen::Matrix<double, 2, 3>* d_pixel_d_point, DistortionModel model) {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  // d(x, y)/dp = [1/Z 0 -x/Z; 0 1/Z -y/Z].
  Eigen::Matrix<double, 2, 3> d_normalised;
  d_normalised << 1.0 / p.z(), 0.0, -x / p.z(), 0.0, 1.0 / p.z(), -y / p.z();
  const Eigen::DiagonalMatrix<double, 2> focal(camera.px, camera.py);
  if (model == DistortionModel::kInverseOfKdu) {
    const Eigen::Vector2d pixel =
        DistortedPixelOf(camera, {camera.u0 + camera.px * x, camera.v0 + camera.py * y});
    if (d_pixel_d_point != nullptr) {
      // The distorted normalised point d solves d (1 + kdu |d|^2) = (x, y): its derivative is
      // the inverse of M = (1 + kdu |d|^2) I + 2 kdu d d^T.
      const double kdu = camera.has_distortion ? camera.kdu : 0.0;
      const Eigen::Vector2d d((pixel.x() - camera.u0) / camera.px,
                              (pixel.y() - camera.v0) / camera.py);
      const Eigen::Matrix2d m = (1.0 + kdu * d.squaredNorm()) * Eigen::Matrix2d::Identity() +
                                2.0 * kdu * d * d.transpose();
      *d_pixel_d_point = focal * (m.inverse() * d_normalised);
    }
    return pixel;
  }
  const double kud = camera.has_distortion ? camera.kud : 0.0;
  const double k = 1.0 + kud * (x * x + y * y);
  if (d_pixel_d_point != nullptr) {
    // d(x k)/dx = k + 2 kud x^2, d(x k)/dy = 2 kud x y.
    Eigen::Matrix2d d_distorted;
    d_distorted << k + 2.0 * kud * x * x, 2.0 * kud * x * y, 2.0 * kud * x * y,
        k + 2.0 * kud * y * y;
    *d_pixel_d_point = focal * (d_distorted * d_normalised);
  }
  return {camera.u0 + camera.px * x * k, camera.v0 + camera.py * y * k};
}

bool PoseLeastSquaresOptions::Check(std::string* why) const {
  if (max_iterations < 1 || !(initial_damping > 0.0) || !(relative_tolerance > 0.0)) {
    *why = "least squares: iterations >= 1, damping and tolerance > 0";
    return false;
  }
  return true;
}

PoseLeastSquaresResult SolvePoseLeastSquares(const PoseResiduals& residuals,
                                             const PoseLeastSquaresOptions& options,
                                             std::vector<Eigen::Isometry3d>* poses) {
  PoseLeastSquaresResult result;
  const Eigen::Index n = 6 * static_cast<Eigen::Index>(poses->size());
  Eigen::VectorXd r, r_try;
  Eigen::MatrixXd jacobian;
  if (!residuals(*poses, &r, &jacobian)) {
    result.failure = "the residuals cannot be evaluated at the start (a point behind the camera)";
    return result;
  }
  result.residuals = static_cast<int>(r.size());
  if (r.size() <= n) {
    result.failure = "no more residuals than parameters";
    return result;
  }
  double cost = r.squaredNorm();
  double lambda = options.initial_damping;
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    // Coefficient-wise products: J is tall and thin, and Eigen's OpenMP-parallel GEMM costs far
    // more than it saves on a loaded machine.
    const Eigen::MatrixXd normal = jacobian.transpose().lazyProduct(jacobian);
    const Eigen::VectorXd gradient = jacobian.transpose().lazyProduct(r);
    bool improved = false;
    double decrease = 0.0, step = 0.0;
    while (lambda < kMaxDamping) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * normal.diagonal();
      const Eigen::VectorXd delta = damped.ldlt().solve(-gradient);
      if (!delta.allFinite()) break;
      const std::vector<Eigen::Isometry3d> trial = Moved(*poses, delta);
      if (residuals(trial, &r_try, nullptr) && r_try.squaredNorm() < cost) {
        decrease = cost - r_try.squaredNorm();
        step = delta.lpNorm<Eigen::Infinity>();
        *poses = trial;
        cost = r_try.squaredNorm();
        lambda = std::max(lambda / 10.0, 1e-15);
        improved = true;
        break;
      }
      lambda *= 10.0;
    }
    if (!improved || !residuals(*poses, &r, &jacobian)) break;
    if (decrease <= options.relative_tolerance * (cost + decrease) || step < kMinStep) break;
  }
  result.cost = cost;
  const Eigen::MatrixXd normal = jacobian.transpose().lazyProduct(jacobian);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normal);
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(eigen.eigenvalues().minCoeff() > kSingularRatio * largest)) {
    result.failure = "a direction of the poses is not observed (J^T J is singular)";
    return result;
  }
  const double s2 = cost / static_cast<double>(r.size() - n);
  result.covariance = s2 * eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                      eigen.eigenvectors().transpose();
  result.ok = true;
  return result;
}

Eigen::MatrixXd NumericPoseJacobian(const PoseResiduals& residuals,
                                    const std::vector<Eigen::Isometry3d>& poses, double h) {
  const Eigen::Index n = 6 * static_cast<Eigen::Index>(poses.size());
  Eigen::VectorXd r0, plus, minus;
  if (!residuals(poses, &r0, nullptr)) return {};
  Eigen::MatrixXd jacobian(r0.size(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(n);
    delta[j] = h;
    if (!residuals(Moved(poses, delta), &plus, nullptr)) return {};
    delta[j] = -h;
    if (!residuals(Moved(poses, delta), &minus, nullptr)) return {};
    jacobian.col(j) = (plus - minus) / (2.0 * h);
  }
  return jacobian;
}

}  // namespace linetrack

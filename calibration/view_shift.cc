#include "calibration/view_shift.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace linetrack {

ViewShiftCovariance EstimateViewShiftCovariance(const Eigen::MatrixXd& jacobian,
                                                const Eigen::VectorXd& residuals,
                                                const std::vector<int>& points_per_view,
                                                double known_tau_px) {
  ViewShiftCovariance out;
  const Eigen::Index m = jacobian.rows(), p = jacobian.cols();
  Eigen::Index rows = 0;
  for (int n : points_per_view)
    rows += 2 * static_cast<Eigen::Index>(n);
  if (rows != m || residuals.size() != m || m <= p || points_per_view.empty()) return out;
  const Eigen::MatrixXd normal = jacobian.transpose().lazyProduct(jacobian);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return out;
  const Eigen::MatrixXd k = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  // Per view, S_v = G_v^T J_v (2 x p: the column sums of its u and v rows) and s_v = G_v^T r_v:
  // J^T B J = sum S_v^T S_v, J^T P J = sum S_v^T S_v / n_v, Q = sum |s_v|^2 / n_v, tr B = 2 N.
  Eigen::MatrixXd jbj = Eigen::MatrixXd::Zero(p, p), jpj = Eigen::MatrixXd::Zero(p, p);
  double q = 0.0;
  Eigen::Index row = 0;
  for (int n : points_per_view) {
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(2, p);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int i = 0; i < n; ++i, row += 2) {
      s += jacobian.middleRows(row, 2);
      sum += residuals.segment<2>(row);
    }
    jbj += s.transpose() * s;
    jpj += s.transpose() * s / static_cast<double>(n);
    q += sum.squaredNorm() / static_cast<double>(n);
  }
  // E[|r|^2] = sigma^2 tr(I - H) + tau^2 tr((I - H) B),
  // E[Q] = sigma^2 tr(P (I - H)) + tau^2 tr(P (I - H) B (I - H)), with H = J K J^T, B P = B.
  const double views = static_cast<double>(points_per_view.size());
  const double sse = residuals.squaredNorm(), trace_b = static_cast<double>(m);
  const double kb = (k * jbj).trace();
  const double a11 = static_cast<double>(m - p), a12 = trace_b - kb;
  const double a21 = 2.0 * views - (k * jpj).trace();
  const double a22 = trace_b - 2.0 * kb + (k * jbj * k * jpj).trace();
  const double det = a11 * a22 - a12 * a21;
  double tau2 = det > 0.0 ? (a11 * q - a21 * sse) / det : 0.0;
  out.tau_data_px = std::sqrt(std::max(tau2, 0.0));
  tau2 = known_tau_px >= 0.0 ? known_tau_px * known_tau_px : std::max(tau2, 0.0);
  const double sigma2 = std::max((sse - tau2 * a12) / a11, 0.0);
  out.sigma_px = std::sqrt(sigma2);
  out.tau_px = std::sqrt(tau2);
  out.covariance = sigma2 * k + tau2 * k * jbj * k;
  out.ok = true;
  return out;
}

}  // namespace linetrack

// The covariance of least-squares poses whose pixel residuals carry, besides independent noise
// of variance sigma^2 per coordinate, a displacement shared by every point of one view: variance
// tau^2 per image axis, independent between views (the image of a per-view pointing error: a
// head angle read off by its encoder's quantisation, or a rendering and detection error common
// to a view). A view's covariance is then sigma^2 I + tau^2 G G^T, G (2n x 2) stacking I_2 per
// point, and the least-squares estimate's covariance is, by propagation (K = (J^T J)^-1),
//   C = sigma^2 K + tau^2 K (sum_v J_v^T G_v G_v^T J_v) K     (docs/calibration.md).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace linetrack {

struct ViewShiftCovariance {
  bool ok = false;
  double sigma_px = 0.0;       // independent noise per coordinate
  double tau_px = 0.0;         // the shared displacement per image axis used in `covariance`
  double tau_data_px = 0.0;    // its moment estimate from the residuals (0 when not positive)
  Eigen::MatrixXd covariance;  // of the parameters (empty when not ok)
};

// The covariance above at a least-squares solution: `jacobian` and `residuals` with the rows of
// view k consecutive (u then v per point, points_per_view[k] points). sigma^2 and tau^2 solve the
// two moment equations E[|r|^2] and E[sum_v |sum_k r_vk|^2 / n_v] of the residuals
// r = (I - H) e (tau^2 >= 0); a known tau (`known_tau_px` >= 0, pixels) replaces the estimate and
// sigma^2 then follows from |r|^2. Not ok when J^T J is singular or the rows do not match.
ViewShiftCovariance EstimateViewShiftCovariance(const Eigen::MatrixXd& jacobian,
                                                const Eigen::VectorXd& residuals,
                                                const std::vector<int>& points_per_view,
                                                double known_tau_px);

}  // namespace linetrack

#include "matching/views/view_combination.h"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <cmath>

namespace linetrack {

std::optional<WeakPerspective> WeakPerspectiveOf(const Eigen::Matrix3d& rotation,
                                                 const Eigen::Vector3d& centre, double z0) {
  const Eigen::Vector3d o = rotation * (Eigen::Vector3d(0.0, 0.0, z0) - centre);
  if (!(o.z() > 0.0)) return std::nullopt;
  WeakPerspective w;
  w.rotation = rotation;
  w.scale = z0 / o.z();
  w.translation = o.head<2>() / o.z();
  return w;
}

std::optional<double> MeanTriangulatedDepth(const std::vector<Eigen::Vector2d>& view1,
                                            const std::vector<Eigen::Vector2d>& view2,
                                            const Eigen::Matrix3d& rotation,
                                            const Eigen::Vector3d& centre) {
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < view1.size() && i < view2.size(); ++i) {
    const Eigen::Vector3d d1(view1[i].x(), view1[i].y(), 1.0);
    const Eigen::Vector3d d2 =
        rotation.transpose() * Eigen::Vector3d(view2[i].x(), view2[i].y(), 1.0);
    // Minimise |l1 d1 - (centre + l2 d2)|^2 over (l1, l2).
    Eigen::Matrix2d a;
    a << d1.dot(d1), -d1.dot(d2), -d1.dot(d2), d2.dot(d2);
    const Eigen::Vector2d b(d1.dot(centre), -d2.dot(centre));
    const double det = a.determinant();
    if (std::abs(det) < 1e-9 * d1.squaredNorm() * d2.squaredNorm()) continue;
    const Eigen::Vector2d l = a.inverse() * b;
    if (l.x() <= 0.0 || l.y() <= 0.0) continue;
    const Eigen::Vector3d point = 0.5 * (l.x() * d1 + centre + l.y() * d2);
    sum += point.z();
    ++count;
  }
  if (count == 0) return std::nullopt;
  return sum / count;
}

std::optional<ViewCombination> FitViewCombination(const std::vector<Eigen::Vector2d>& view1,
                                                  const std::vector<double>& view2_x,
                                                  const std::vector<Eigen::Vector2d>& novel) {
  const int n = static_cast<int>(view1.size());
  if (n < 4 || static_cast<int>(view2_x.size()) != n || static_cast<int>(novel.size()) != n) {
    return std::nullopt;
  }
  Eigen::MatrixXd basis(n, 4);
  Eigen::VectorXd xs(n), ys(n);
  for (int i = 0; i < n; ++i) {
    basis.row(i) << view1[i].x(), view1[i].y(), view2_x[i], 1.0;
    xs[i] = novel[i].x();
    ys[i] = novel[i].y();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(basis, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (sv(3) <= 1e-9 * sv(0)) return std::nullopt;
  ViewCombination out;
  out.a = svd.solve(xs);
  out.b = svd.solve(ys);
  out.rms = std::sqrt(((basis * out.a - xs).squaredNorm() + (basis * out.b - ys).squaredNorm()) /
                      (2.0 * n));
  return out;
}

NovelView RecoverNovelView(const ViewCombination& combination, const WeakPerspective& view2,
                           double z0) {
  const Eigen::Matrix3d& r = view2.rotation;
  const double s = view2.scale;
  const Eigen::Vector4d& a = combination.a;
  const Eigen::Vector4d& b = combination.b;
  const Eigen::Vector3d row1(a[0] + a[2] * s * r(0, 0), a[1] + a[2] * s * r(0, 1),
                             a[2] * s * r(0, 2));
  const Eigen::Vector3d row2(b[0] + b[2] * s * r(0, 0), b[1] + b[2] * s * r(0, 1),
                             b[2] * s * r(0, 2));
  NovelView out;
  out.scale_a = row1.norm();
  out.scale_b = row2.norm();
  const Eigen::Vector3d u1 = row1 / out.scale_a, u2 = row2 / out.scale_b;
  out.orthogonality = u1.dot(u2);
  Eigen::Matrix3d m;
  m.row(0) = u1.transpose();
  m.row(1) = u2.transpose();
  m.row(2) = u1.cross(u2).normalized().transpose();
  // The nearest rotation to m (Frobenius norm).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  out.rotation = svd.matrixU() * d * svd.matrixV().transpose();
  out.translation = {a[2] * view2.translation.x() + a[3], b[2] * view2.translation.x() + b[3]};
  const double scale = 0.5 * (out.scale_a + out.scale_b);
  const double depth = z0 / scale;  // o_z of the reference point in the novel camera
  const Eigen::Vector3d o(out.translation.x() * depth, out.translation.y() * depth, depth);
  out.centre = Eigen::Vector3d(0.0, 0.0, z0) - out.rotation.transpose() * o;
  return out;
}

}  // namespace linetrack

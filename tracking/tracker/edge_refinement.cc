#include "tracking/tracker/edge_refinement.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>

#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "tracking/tracker/image_sampling.h"

namespace linetrack {

namespace {

constexpr double kNearClip = 0.05;   // metres
constexpr double kSampleStep = 0.5;  // pixels between samples of the edge profile
constexpr double kJacobianStep = 1e-6;
// The edge profile extends this far beyond the search window on each side, so that the flanks of
// a blurred step whose peak lies near the window's end are inside it (pixels).
constexpr double kProfileMarginPx = 1.0;

// A model edge as seen from the start pose (its 3D part inside the view, clipped to the frustum)
// and the sub-pixel edge points attached to it.
using ViewedEdge = EdgeObservation;

// Left-multiplied update: exp([omega, v]) * pose, in the camera frame.
Eigen::Isometry3d Update(const Eigen::Isometry3d& pose, const Eigen::Matrix<double, 6, 1>& delta) {
  const Eigen::Vector3d omega = delta.head<3>();
  const double angle = omega.norm();
  const Eigen::Matrix3d r = angle > 0.0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                                        : Eigen::Matrix3d::Identity();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = r * pose.linear();
  out.translation() = r * pose.translation() + delta.tail<3>();
  return out;
}

// Signed distances of the edge points to the projected edges under `pose`; false when an edge
// falls behind the camera.
bool Residuals(const std::vector<ViewedEdge>& edges, const CameraIntrinsics& camera,
               const Eigen::Isometry3d& pose, Eigen::VectorXd* residuals) {
  int k = 0;
  for (const ViewedEdge& edge : edges) {
    const Eigen::Vector3d a = pose * edge.a, b = pose * edge.b;
    if (a.z() <= kNearClip * 0.5 || b.z() <= kNearClip * 0.5) return false;
    const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
    const Eigen::Vector2d d = pb - pa;
    const double length = d.norm();
    if (!(length > 1e-9)) return false;
    const Eigen::Vector2d normal(-d.y() / length, d.x() / length);
    for (const Eigen::Vector2d& p : edge.points)
      (*residuals)[k++] = normal.dot(p - pa);
  }
  return true;
}

double WeightedCost(const Eigen::VectorXd& r, double huber) {
  double cost = 0.0;
  for (int i = 0; i < r.size(); ++i) {
    const double a = std::abs(r[i]);
    cost += a <= huber ? 0.5 * a * a : huber * (a - 0.5 * huber);
  }
  return cost;
}

double Rms(const Eigen::VectorXd& r) {
  return r.size() ? std::sqrt(r.squaredNorm() / r.size()) : 0.0;
}

// The pose as a function of the unknowns: 6 (a left-multiplied twist on the start pose) or, with
// a known height, tilt and roll, 3 (x, y, heading of the robot pose).
class PoseParameters {
 public:
  PoseParameters(const Eigen::Isometry3d& start, const std::optional<KnownHeightTilt>& known)
      : start_(start), known_(known) {
    if (known_) {
      const RobotPose robot = RobotPoseFromCamFromWorld(start);
      base_ = Eigen::Vector3d(robot.x, robot.y, robot.heading);
    }
  }
  int size() const { return known_ ? 3 : 6; }
  Eigen::Isometry3d Pose(const Eigen::VectorXd& p) const {
    if (!known_) return Update(start_, p);
    return CamFromWorld(RobotPose{base_.x() + p[0], base_.y() + p[1], base_.z() + p[2],
                                  known_->height, known_->tilt, known_->roll});
  }

 private:
  Eigen::Isometry3d start_;
  std::optional<KnownHeightTilt> known_;
  Eigen::Vector3d base_ = Eigen::Vector3d::Zero();
};

// The unknowns of a solve, its residuals (pixels, one per edge point) and J^T W J at them.
struct IrlsState {
  Eigen::VectorXd p, r;
  Eigen::MatrixXd information;
};

// Iteratively reweighted Gauss-Newton (Huber weights) on the point-to-line distances of the edge
// points of `edges`, from the parameters state->p (updated, r sized to the points). state->r
// receives the residuals at the result and state->information J^T W J there. False when an edge
// falls behind the camera or a step fails.
bool SolveIrls(const std::vector<ViewedEdge>& edges, const CameraIntrinsics& camera,
               const PoseParameters& parameters, const EdgeRefinementOptions& options,
               IrlsState* state) {
  Eigen::VectorXd* p = &state->p;
  Eigen::VectorXd* r = &state->r;
  Eigen::MatrixXd* information = &state->information;
  const int dof = parameters.size();
  const int n = static_cast<int>(r->size());
  Eigen::VectorXd r_step(n), w(n);
  Eigen::MatrixXd jacobian(n, dof);
  auto linearise = [&]() {
    for (int j = 0; j < dof; ++j) {
      Eigen::VectorXd stepped = *p;
      stepped[j] += kJacobianStep;
      if (!Residuals(edges, camera, parameters.Pose(stepped), &r_step)) return false;
      jacobian.col(j) = (r_step - *r) / kJacobianStep;
    }
    for (int i = 0; i < n; ++i) {
      const double a = std::abs((*r)[i]);
      w[i] = a <= options.huber_px ? 1.0 : options.huber_px / a;
    }
    *information = jacobian.transpose() * w.asDiagonal() * jacobian;
    return true;
  };
  if (!Residuals(edges, camera, parameters.Pose(*p), r)) return false;
  for (int it = 0; it < options.iterations; ++it) {
    if (!linearise()) return false;
    const Eigen::VectorXd g = jacobian.transpose() * w.asDiagonal() * *r;
    const Eigen::VectorXd delta = -information->ldlt().solve(g);
    if (!delta.allFinite()) return false;
    *p += delta;
    if (!Residuals(edges, camera, parameters.Pose(*p), r)) return false;
  }
  return linearise();
}

// Mean signed residual of each edge's points (pixels), in the order of `edges`.
std::vector<double> EdgeMeanResiduals(const std::vector<ViewedEdge>& edges,
                                      const Eigen::VectorXd& r) {
  std::vector<double> means;
  int k = 0;
  for (const ViewedEdge& e : edges) {
    const int m = static_cast<int>(e.points.size());
    means.push_back(r.segment(k, m).mean());
    k += m;
  }
  return means;
}

int PointCount(const std::vector<ViewedEdge>& edges) {
  int n = 0;
  for (const ViewedEdge& e : edges)
    n += static_cast<int>(e.points.size());
  return n;
}

// Refines `start` on the edge points: iteratively reweighted Gauss-Newton, then edge by edge the
// edge whose points lie on average farthest from it (beyond edge_outlier_px: its points are on an
// unmodelled parallel line, e.g. the outer border of a door casing) is set aside and the pose
// solved again. Per-point weights cannot do this: all the points of such an edge agree.
EdgeRefinement SolveOnEdgePoints(std::vector<ViewedEdge> viewed, const CameraIntrinsics& camera,
                                 const Eigen::Isometry3d& start,
                                 const std::optional<KnownHeightTilt>& known,
                                 const EdgeRefinementOptions& options) {
  EdgeRefinement out;
  out.cam_from_world = start;
  std::vector<ViewedEdge> used;
  for (ViewedEdge& e : viewed) {
    if (!e.points.empty()) used.push_back(std::move(e));
  }
  out.points = PointCount(used);
  out.refusal = "too few points";
  if (out.points < options.min_points) return out;

  const PoseParameters parameters(start, known);
  const int dof = parameters.size();
  IrlsState solve;
  Eigen::VectorXd& r = solve.r;
  r.resize(out.points);
  out.refusal = "an edge behind the camera";
  if (!Residuals(used, camera, start, &r)) return out;
  out.rms_before_px = Rms(r);

  const Eigen::VectorXd& p = solve.p;
  const Eigen::MatrixXd& information = solve.information;
  std::vector<ViewedEdge> set_aside;
  for (int rejections = 0;; ++rejections) {
    const int n = PointCount(used);
    out.refusal = "too few points after setting edges aside";
    if (n < options.min_points) return out;
    solve.p = Eigen::VectorXd::Zero(dof);
    r.resize(n);
    out.refusal = "the solve failed";
    if (!SolveIrls(used, camera, parameters, options, &solve)) return out;
    if (rejections == options.max_edge_rejections) break;
    const std::vector<double> means = EdgeMeanResiduals(used, r);
    int worst = -1;
    for (size_t e = 0; e < means.size(); ++e) {
      if (std::abs(means[e]) > options.edge_outlier_px &&
          (worst < 0 || std::abs(means[e]) > std::abs(means[worst]))) {
        worst = static_cast<int>(e);
      }
    }
    if (worst < 0) break;
    out.rejected_points += static_cast<int>(used[worst].points.size());
    ++out.rejected_edges;
    set_aside.push_back(std::move(used[worst]));
    used.erase(used.begin() + worst);
  }
  const Eigen::Isometry3d pose = parameters.Pose(p);
  out.rms_after_px = Rms(r);
  // The kept points must fit better than at the start (with a known height and tilt the start
  // may lie off the constraint: its image on the constraint instead).
  Eigen::VectorXd r_start(r.size());
  const Eigen::Isometry3d reference = known ? parameters.Pose(Eigen::VectorXd::Zero(dof)) : start;
  if (!Residuals(used, camera, reference, &r_start)) return out;
  out.refusal = "no better fit than the start";
  if (!(WeightedCost(r, options.huber_px) <= WeightedCost(r_start, options.huber_px))) return out;
  // Refuse large corrections: they mean the edge points were not where they were looked for.
  double motion = 0.0;
  for (const ViewedEdge& e : used) {
    motion += (camera.Project(pose * e.a) - camera.Project(start * e.a)).norm() +
              (camera.Project(pose * e.b) - camera.Project(start * e.b)).norm();
  }
  char text[64];
  std::snprintf(text, sizeof(text), "correction %.1f px", motion / (2.0 * used.size()));
  out.refusal = text;
  if (!(motion / (2.0 * used.size()) <= options.max_correction_px)) return out;
  out.applied = true;
  out.refusal.clear();
  out.cam_from_world = pose;
  out.points = PointCount(used);
  out.observations = std::move(used);
  out.set_aside = std::move(set_aside);
  // Standard deviations from the Gauss-Newton information and the residuals' scale.
  const double scale2 = r.squaredNorm() / std::max(1, static_cast<int>(r.size()) - dof);
  const Eigen::MatrixXd covariance = scale2 * information.inverse();
  if (known && covariance.allFinite()) {
    out.position_sigma_m = std::sqrt(std::max(
        0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(covariance.topLeftCorner<2, 2>())
                 .eigenvalues()
                 .maxCoeff()));
    out.heading_sigma_rad = std::sqrt(std::max(0.0, covariance(2, 2)));
  }
  return out;
}

}  // namespace

bool EdgeRefinementOptions::Check(std::string* why) const {
  if (!(association_px > 0.0) || !(ambiguity_px >= association_px) || !(end_margin_px >= 0.0) ||
      !(search_px >= 1.0 && search_px <= 10.0)) {
    *why = "edge refinement: association > 0, ambiguity >= association, search in [1, 10] px";
    return false;
  }
  if (!(edge_outlier_px > 0.0) || max_edge_rejections < 0) {
    *why = "edge refinement: edge outlier distance > 0, rejections >= 0";
    return false;
  }
  if (!(min_gradient > 0.0) || !(huber_px > 0.0) || iterations < 1 || min_points < 6 ||
      !(max_correction_px > 0.0)) {
    *why =
        "edge refinement: positive gradient, Huber width and correction; >= 1 iteration, >= 6 "
        "points";
    return false;
  }
  return true;
}

bool EdgeAlignmentOptions::Check(std::string* why) const {
  if (!solve.Check(why)) return false;
  if (!(sample_step_px >= 1.0) || !(search_px >= solve.search_px && search_px <= 50.0) ||
      rounds < 1 || rounds > 5) {
    *why = "edge alignment: sample step >= 1 px, search in [refinement search, 50] px, 1-5 rounds";
    return false;
  }
  return true;
}

double SubpixelEdgeOffset(const vpImage<unsigned char>& image, const Eigen::Vector2d& point,
                          const Eigen::Vector2d& normal, double search_px, double min_gradient) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d tangent(-normal.y(), normal.x());
  const int half = static_cast<int>(std::ceil((search_px + kProfileMarginPx) / kSampleStep)) + 1;
  std::vector<double> profile(2 * half + 1);
  for (int k = -half; k <= half; ++k) {
    double sum = 0.0;
    for (int s = -1; s <= 1; ++s) {
      double value = 0.0;
      if (!SampleBilinear(image, point + k * kSampleStep * normal + s * tangent, &value))
        return nan;
      sum += value;
    }
    profile[k + half] = sum / 3.0;
  }
  // Derivative at k = -half + 1 .. half - 1; its largest magnitude must lie within the window.
  std::vector<double> derivative(profile.size(), 0.0);
  int best = -1;
  double best_magnitude = -1.0;
  for (int k = 1; k + 1 < static_cast<int>(profile.size()); ++k) {
    derivative[k] = (profile[k + 1] - profile[k - 1]) / (2.0 * kSampleStep);
    if (std::abs((k - half) * kSampleStep) <= search_px &&
        std::abs(derivative[k]) > best_magnitude) {
      best_magnitude = std::abs(derivative[k]);
      best = k;
    }
  }
  if (best < 0 || best_magnitude < min_gradient) return nan;
  // Centroid of the derivative over the step (same sign, above a quarter of the peak): unbiased
  // for a step blurred symmetrically, and for the piecewise-linear profile of a sharp one.
  const double sign = derivative[best] > 0.0 ? 1.0 : -1.0;
  int lo = best, hi = best;
  while (lo > 1 && sign * derivative[lo - 1] >= 0.25 * best_magnitude)
    --lo;
  while (hi + 2 < static_cast<int>(profile.size()) &&
         sign * derivative[hi + 1] >= 0.25 * best_magnitude) {
    ++hi;
  }
  if (lo <= 1 || hi + 2 >= static_cast<int>(profile.size())) return nan;  // step cut by the window
  double weight = 0.0, moment = 0.0;
  for (int k = lo; k <= hi; ++k) {
    weight += sign * derivative[k];
    moment += sign * derivative[k] * (k - half);
  }
  return moment / weight * kSampleStep;
}

EdgeRefinement RefineOnEdges(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                             const std::vector<Segment3>& edges,
                             const std::vector<Eigen::Vector2d>& sites, const RefinementStart& from,
                             const EdgeRefinementOptions& options) {
  const Eigen::Isometry3d& start = from.cam_from_world;
  // The model edges in view and their images at the start pose.
  std::vector<ViewedEdge> viewed;
  std::vector<Segment2> images;
  for (size_t index = 0; index < edges.size(); ++index) {
    Segment3 clipped = edges[index];
    if (!ClipToFrustum(start, camera, kNearClip, &clipped)) continue;
    const Segment2 image_edge{camera.Project(start * clipped.a), camera.Project(start * clipped.b)};
    if (image_edge.Length() < 2.0 * options.end_margin_px + 2.0) continue;
    viewed.push_back(ViewedEdge{clipped.a, clipped.b, {}, static_cast<int>(index)});
    images.push_back(image_edge);
  }
  // Each site goes to the one projected edge it lies on, then to the sub-pixel step near it.
  for (const Eigen::Vector2d& site : sites) {
    int best = -1;
    double best_distance = options.ambiguity_px, second = options.ambiguity_px;
    for (size_t e = 0; e < images.size(); ++e) {
      const Eigen::Vector2d d = images[e].b - images[e].a;
      const double length = d.norm();
      const double along = (site - images[e].a).dot(d) / length;
      if (along < options.end_margin_px || along > length - options.end_margin_px) continue;
      const double distance = std::abs(Cross2(d, site - images[e].a)) / length;
      if (distance < best_distance) {
        second = best_distance;
        best_distance = distance;
        best = static_cast<int>(e);
      } else if (distance < second) {
        second = distance;
      }
    }
    if (best < 0 || best_distance > options.association_px || second < options.ambiguity_px) {
      continue;
    }
    const Eigen::Vector2d d = (images[best].b - images[best].a).normalized();
    const Eigen::Vector2d normal(-d.y(), d.x());
    const double offset =
        SubpixelEdgeOffset(image, site, normal, options.search_px, options.min_gradient);
    if (std::isfinite(offset)) viewed[best].points.push_back(site + offset * normal);
  }
  return SolveOnEdgePoints(std::move(viewed), camera, start, from.known, options);
}

EdgeRefinement AlignToEdges(const vpImage<unsigned char>& image, const CameraIntrinsics& camera,
                            const std::vector<Segment3>& visible, const RefinementStart& from,
                            const EdgeAlignmentOptions& options) {
  const Eigen::Isometry3d& start = from.cam_from_world;
  const std::optional<KnownHeightTilt>& known = from.known;
  EdgeRefinement out;
  out.cam_from_world = start;
  Eigen::Isometry3d pose = start;
  for (int round = 0; round < options.rounds; ++round) {
    EdgeRefinementOptions solve = options.solve;
    solve.search_px = round == 0 ? options.search_px : options.solve.search_px;
    solve.max_correction_px = solve.search_px;
    std::vector<ViewedEdge> viewed;
    for (size_t index = 0; index < visible.size(); ++index) {
      Segment3 clipped = visible[index];
      if (!ClipToFrustum(pose, camera, kNearClip, &clipped)) continue;
      const Eigen::Vector2d a = camera.Project(pose * clipped.a);
      const Eigen::Vector2d b = camera.Project(pose * clipped.b);
      const double length = (b - a).norm();
      if (length < 2.0 * solve.end_margin_px + options.sample_step_px) continue;
      const Eigen::Vector2d d = (b - a) / length;
      const Eigen::Vector2d normal(-d.y(), d.x());
      ViewedEdge edge{clipped.a, clipped.b, {}, static_cast<int>(index)};
      for (double s = solve.end_margin_px; s <= length - solve.end_margin_px;
           s += options.sample_step_px) {
        const Eigen::Vector2d p = a + s * d;
        const double offset =
            SubpixelEdgeOffset(image, p, normal, solve.search_px, solve.min_gradient);
        if (std::isfinite(offset)) edge.points.push_back(p + offset * normal);
      }
      viewed.push_back(std::move(edge));
    }
    const EdgeRefinement step = SolveOnEdgePoints(std::move(viewed), camera, pose, known, solve);
    if (!step.applied) return out;
    if (round == 0) out.rms_before_px = step.rms_before_px;
    pose = step.cam_from_world;
    out.points = step.points;
    out.rms_after_px = step.rms_after_px;
    out.observations = step.observations;
    out.set_aside = step.set_aside;
  }
  out.applied = true;
  out.cam_from_world = pose;
  return out;
}

}  // namespace linetrack

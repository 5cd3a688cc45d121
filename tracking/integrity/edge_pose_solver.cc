#include "tracking/integrity/edge_pose_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace linetrack {

namespace {

constexpr double kMadToSigma = 1.4826;  // standard deviation / median absolute deviation, normal
constexpr double kChi2TwoMedian = 1.3862943611198906;  // 2 ln 2
constexpr double kNearClipM = 0.01;
constexpr double kMinEigenRatio = 1e-12;  // information below this share of its largest axis
constexpr int kScaleBisections = 40;

// Small matrices of at most 9 x 9 (the state: pose and estimated parameters; the held
// parameters), on the stack.
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 9, 9>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 9, 1>;

// One edge linearised at a pose: residuals, Jacobians in the unknowns and in the considered
// parameters, the endpoint basis U (rows (1 - t, t)) and the edge-level covariance; then the
// points' Huber weights.
struct EdgeLinearisation {
  int observation = -1;
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;    // m x dof
  Eigen::MatrixXd considered;  // m x p
  Eigen::MatrixXd basis;       // m x 2
  Eigen::Matrix2d edge_covariance = Eigen::Matrix2d::Zero();
  Eigen::VectorXd within;   // residuals about the edge's own best line (m >= 3), else empty
  Eigen::VectorXd weights;  // Huber weights of the points
};

// The point sums of one edge with D = weights / sigma^2: J'DJ, J'DC, J'DU, U'DC, U'DU, J'Dr,
// U'Dr, r'Dr. Whitening them for any edge-level scale costs 2 x 2 algebra only.
struct EdgeSums {
  int observation = -1;
  int points = 0;
  Small jdj, jdc, jdu, udc;
  Eigen::Matrix2d udu = Eigen::Matrix2d::Zero();
  SmallVector jdr;
  Eigen::Vector2d udr = Eigen::Vector2d::Zero();
  double rdr = 0.0;
  Eigen::Matrix2d edge_covariance = Eigen::Matrix2d::Zero();
};

bool Linearise(const EdgeObservation& observation, const CameraIntrinsics& camera,
               const Eigen::Isometry3d& pose, const PoseParameterisation& parameters,
               const EdgeNoiseOptions& noise, EdgeLinearisation* out) {
  const Eigen::Vector3d a = pose * observation.a, b = pose * observation.b;
  if (!(a.z() > kNearClipM && b.z() > kNearClipM)) return false;
  const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
  const Eigen::Vector2d d = pb - pa;
  if (!(d.squaredNorm() > 1e-12)) return false;
  const EdgeLineProjection line(observation.a, observation.b, pose, camera);
  // d n / d x and d n / d (height, tilt, roll): 3 x dof and 3 x (0 or 3).
  using NormalMap = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 6>;
  const NormalMap normal_of_unknowns = line.NormalOfTwist() * parameters.TwistOfUnknowns();
  const NormalMap normal_of_robot = line.NormalOfTwist() * parameters.TwistOfRobotParameters(pose);
  const int m = static_cast<int>(observation.points.size());
  out->residuals.resize(m);
  out->jacobian.resize(m, parameters.dof());
  out->considered.resize(m, parameters.considered());
  out->basis.resize(m, 2);
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2d& p = observation.points[i];
    const EdgePointResidual r = line.At(p);
    out->residuals[i] = r.residual;
    out->jacobian.row(i).noalias() = r.d_normal.transpose() * normal_of_unknowns;
    out->considered.row(i).head<3>() = r.d_camera;
    if (parameters.robot())
      out->considered.row(i).tail<3>().noalias() = r.d_normal.transpose() * normal_of_robot;
    const double t = (p - pa).dot(d) / d.squaredNorm();
    out->basis.row(i) << 1.0 - t, t;
  }
  out->edge_covariance = EdgeLevelCovariance(a.z(), b.z(), 0.5 * (camera.px + camera.py), noise);
  if (noise.casing_sigma_m > 0.0 && !observation.casing_direction.isZero()) {
    const Eigen::Vector2d k = CasingOffsets(observation, pose, camera);
    out->edge_covariance += noise.casing_sigma_m * noise.casing_sigma_m * k * k.transpose();
  }
  return true;
}

// Moves the estimated parameters' columns of the considered Jacobian J_c into the state's
// Jacobian and their current deviation c^ into the residuals, r(c^) = r(c0) + J_c c^ (first
// order: c^ is a fraction of a degree, pixel or per cent); the held columns stay considered.
void Augment(const EdgePoseSolution& state, EdgeLinearisation* e) {
  const int dof = static_cast<int>(e->jacobian.cols());
  const int q = static_cast<int>(state.estimated.size());
  const Eigen::MatrixXd full = e->considered;
  e->jacobian.conservativeResize(Eigen::NoChange, dof + q);
  for (int j = 0; j < q; ++j) {
    e->jacobian.col(dof + j) = full.col(state.estimated[j]);
    e->residuals += full.col(state.estimated[j]) * state.parameter_deviation[j];
  }
  e->considered.resize(full.rows(), state.held.size());
  for (size_t j = 0; j < state.held.size(); ++j)
    e->considered.col(j) = full.col(state.held[j]);
}

// The residuals of each edge about its own least-squares line (offset and slope in the endpoint
// basis), for edges of 3 points or more.
void FitWithinEdges(std::vector<EdgeLinearisation>* edges) {
  for (EdgeLinearisation& e : *edges) {
    e.within.resize(0);
    if (e.residuals.size() < 3) continue;
    const Eigen::Matrix2d gram = e.basis.transpose() * e.basis;
    if (!(std::abs(gram.determinant()) > 1e-12)) continue;
    const Eigen::Vector2d beta = gram.inverse() * (e.basis.transpose() * e.residuals);
    e.within = e.residuals - e.basis * beta;
  }
}

// Point sigma (1.4826 MAD of the within-edge residuals, corrected for the two parameters each
// edge's line takes, floored) and the points' Huber weights.
double EstimatePointSigma(const EdgeNoiseOptions& noise, std::vector<EdgeLinearisation>* edges) {
  FitWithinEdges(edges);
  std::vector<double> deviations;
  int lines = 0;
  for (const EdgeLinearisation& e : *edges) {
    if (e.within.size() == 0) continue;
    ++lines;
    for (int i = 0; i < e.within.size(); ++i)
      deviations.push_back(std::abs(e.within[i]));
  }
  double sigma = noise.min_point_sigma_px;
  const int n = static_cast<int>(deviations.size());
  if (n > 2 * lines) {
    std::nth_element(deviations.begin(), deviations.begin() + n / 2, deviations.end());
    const double mad = kMadToSigma * deviations[n / 2];
    sigma = std::max(sigma, mad * std::sqrt(static_cast<double>(n) / (n - 2 * lines)));
  }
  for (EdgeLinearisation& e : *edges) {
    e.weights = Eigen::VectorXd::Ones(e.residuals.size());
    for (int i = 0; i < e.within.size(); ++i) {
      const double a = std::abs(e.within[i]);
      if (a > noise.huber_sigmas * sigma) e.weights[i] = noise.huber_sigmas * sigma / a;
    }
  }
  return sigma;
}

EdgeSums Accumulate(const EdgeLinearisation& e, double sigma) {
  const int dof = static_cast<int>(e.jacobian.cols());
  const int p = static_cast<int>(e.considered.cols());
  EdgeSums s;
  s.observation = e.observation;
  s.points = static_cast<int>(e.residuals.size());
  s.edge_covariance = e.edge_covariance;
  s.jdj = Small::Zero(dof, dof);
  s.jdc = Small::Zero(dof, p);
  s.jdu = Small::Zero(dof, 2);
  s.udc = Small::Zero(2, p);
  s.jdr = SmallVector::Zero(dof);
  for (int i = 0; i < s.points; ++i) {
    const double w = e.weights[i] / (sigma * sigma), r = e.residuals[i];
    const SmallVector j = e.jacobian.row(i).transpose();
    const SmallVector c = e.considered.row(i).transpose();
    const Eigen::Vector2d u = e.basis.row(i).transpose();
    s.jdj.noalias() += w * j * j.transpose();
    s.jdc.noalias() += w * j * c.transpose();
    s.jdu.noalias() += w * j * u.transpose();
    s.udc.noalias() += w * u * c.transpose();
    s.udu.noalias() += w * u * u.transpose();
    s.jdr += w * r * j;
    s.udr += w * r * u;
    s.rdr += w * r * r;
  }
  return s;
}

// The edge-level variance factor lambda >= 1: the median over edges of beta_e' (lambda S_e +
// M_e^-1 + F_e Sc F_e')^-1 beta_e (beta_e = M_e^-1 U'Dr the edge's own fitted end offsets,
// M_e = U'DU, F_e = M_e^-1 U'D (J_c - J L) the offsets that errors of the considered parameters
// leave once the pose has absorbed what it can, L = A^-1 B) brought to chi2(2)'s median times
// (2E - dof) / 2E, the share of the edges' freedom the pose leaves. `lean` L may be empty.
double EstimateEdgeScale(const std::vector<EdgeSums>& edges, int dof, const Eigen::MatrixXd& lean,
                         const Eigen::MatrixXd& considered, const EdgeNoiseOptions& noise) {
  struct Offsets {
    Eigen::Vector2d beta;
    Eigen::Matrix2d fixed_covariance, edge_covariance;
  };
  std::vector<Offsets> offsets;
  for (const EdgeSums& e : edges) {
    if (!(std::abs(e.udu.determinant()) > 1e-12 * e.udu.squaredNorm())) continue;
    const Eigen::Matrix2d inverse = e.udu.inverse();
    Eigen::Matrix2d fixed = inverse;
    if (lean.size() > 0) {
      const Small f = inverse * (e.udc - e.jdu.transpose() * lean);  // 2 x p
      fixed += f * considered * f.transpose();
    }
    offsets.push_back({inverse * e.udr, fixed, e.edge_covariance});
  }
  const int count = static_cast<int>(offsets.size());
  if (2 * count - dof < 1) return 1.0;
  const double target = kChi2TwoMedian * (2.0 * count - dof) / (2.0 * count);
  std::vector<double> q(count);
  auto median_q = [&](double lambda) {
    for (int k = 0; k < count; ++k) {
      const Offsets& o = offsets[k];
      q[k] = o.beta.dot((lambda * o.edge_covariance + o.fixed_covariance).ldlt().solve(o.beta));
    }
    std::nth_element(q.begin(), q.begin() + count / 2, q.end());
    return q[count / 2];
  };
  if (median_q(1.0) <= target) return 1.0;
  if (median_q(noise.max_edge_scale) >= target) return noise.max_edge_scale;
  double lo = 0.0, hi = std::log(noise.max_edge_scale);
  for (int it = 0; it < kScaleBisections; ++it) {
    const double mid = 0.5 * (lo + hi);
    (median_q(std::exp(mid)) > target ? lo : hi) = mid;
  }
  return std::exp(hi);
}

// The edge's whitened terms (EdgeBlock) for edge-level factor lambda: K'S^-1L = K'DL - (K'DU) G
// (U'DL) with the Woodbury kernel G.
EdgeBlock WhitenEdge(const EdgeSums& e, double lambda) {
  const Eigen::Matrix2d kernel = WoodburyKernel(lambda * e.edge_covariance, e.udu);
  const Small jdu_kernel = e.jdu * kernel;
  EdgeBlock block;
  block.observation = e.observation;
  block.points = e.points;
  block.information = e.jdj - jdu_kernel * e.jdu.transpose();
  block.gradient = e.jdr - jdu_kernel * e.udr;
  block.coupling = e.jdc - jdu_kernel * e.udc;
  block.offset_coupling = e.jdu - jdu_kernel * e.udu;
  block.chi2 = e.rdr - e.udr.dot(kernel * e.udr);
  return block;
}

// True when `information` is positive definite with its smallest axis above kMinEigenRatio of
// its largest.
bool WellConditioned(const Eigen::MatrixXd& information) {
  if (!information.allFinite()) return false;
  const Eigen::VectorXd eigen =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(information).eigenvalues();
  return eigen.minCoeff() > kMinEigenRatio * eigen.maxCoeff() && eigen.maxCoeff() > 0.0;
}

// The edges' whitened blocks and their sums (information, coupling, gradient, chi2) for the
// edge-level factor `lambda`.
void Sum(const std::vector<EdgeSums>& edges, double lambda, EdgePoseSolution* out) {
  const int n = out->state_size();
  out->information = Eigen::MatrixXd::Zero(n, n);
  out->coupling = Eigen::MatrixXd::Zero(n, out->held.size());
  out->gradient = Eigen::VectorXd::Zero(n);
  out->chi2 = 0.0;
  out->edges.clear();
  for (const EdgeSums& e : edges) {
    out->edges.push_back(WhitenEdge(e, lambda));
    out->information += out->edges.back().information;
    out->coupling += out->edges.back().coupling;
    out->gradient += out->edges.back().gradient;
    out->chi2 += out->edges.back().chi2;
  }
}

// Adds the priors to the sums: the estimated parameters' N(0, Sc) on their deviations c^ (never
// an edge's, so never downdated) and the pose prior's information on the unknowns.
void AddPriors(const std::optional<PosePrior>& prior, const Eigen::Isometry3d& pose,
               const Eigen::MatrixXd& full_considered, EdgePoseSolution* out) {
  const int dof = out->parameters.dof();
  for (size_t j = 0; j < out->estimated.size(); ++j) {
    const int i = out->estimated[j];
    const double information = 1.0 / full_considered(i, i);
    const double c = out->parameter_deviation[j];
    out->information(dof + j, dof + j) += information;
    out->gradient[dof + j] += information * c;
    out->chi2 += information * c * c;
  }
  if (!prior) return;
  const Eigen::MatrixXd prior_information = prior->covariance.inverse();
  const Eigen::VectorXd offset = out->parameters.Difference(pose, prior->cam_from_world);
  out->information.topLeftCorner(dof, dof) += prior_information;
  out->gradient.head(dof) += prior_information * offset;
  out->chi2 += offset.dot(prior_information * offset);
}

// Linearises every kept observation at `pose` and fills the solution's blocks and sums; false
// (with the reason) when an edge falls behind the camera or too few points remain.
bool Assemble(const std::vector<EdgeObservation>& observations, const CameraIntrinsics& camera,
              const Eigen::Isometry3d& pose, const EdgePoseSolverOptions& options,
              const std::vector<bool>& excluded, const std::optional<PosePrior>& prior,
              EdgePoseSolution* out) {
  const PoseParameterisation& parameters = out->parameters;
  std::vector<EdgeLinearisation> edges;
  out->points = 0;
  for (size_t k = 0; k < observations.size(); ++k) {
    if (k < excluded.size() && excluded[k]) continue;
    if (static_cast<int>(observations[k].points.size()) < options.min_points_per_edge) continue;
    EdgeLinearisation e;
    e.observation = static_cast<int>(k);
    if (!Linearise(observations[k], camera, pose, parameters, options.noise, &e)) {
      out->reason = "a model edge falls behind the camera";
      return false;
    }
    Augment(*out, &e);
    out->points += static_cast<int>(e.residuals.size());
    edges.push_back(std::move(e));
  }
  if (out->points < options.min_points) {
    out->reason = "too few edge points (" + std::to_string(out->points) + ")";
    return false;
  }
  out->point_sigma_px = EstimatePointSigma(options.noise, &edges);
  std::vector<EdgeSums> sums;
  for (const EdgeLinearisation& e : edges)
    sums.push_back(Accumulate(e, out->point_sigma_px));
  const Eigen::MatrixXd full_considered = options.considered.Covariance(parameters);
  out->considered = Eigen::MatrixXd::Zero(out->held.size(), out->held.size());
  for (size_t j = 0; j < out->held.size(); ++j)
    out->considered(j, j) = full_considered(out->held[j], out->held[j]);
  out->edge_scale = 1.0;
  if (options.noise.estimate_edge_scale) {
    Sum(sums, 1.0, out);  // lambda needs the lean A^-1 B of the solve at lambda = 1
    AddPriors(prior, pose, full_considered, out);
    const Eigen::MatrixXd lean = WellConditioned(out->information)
                                     ? Eigen::MatrixXd(out->information.ldlt().solve(out->coupling))
                                     : Eigen::MatrixXd();
    out->edge_scale =
        EstimateEdgeScale(sums, parameters.dof(), lean, out->considered, options.noise);
  }
  Sum(sums, out->edge_scale, out);
  AddPriors(prior, pose, full_considered, out);
  out->cam_from_world = pose;
  return true;
}

}  // namespace

bool EdgeNoiseOptions::Check(std::string* why) const {
  if (!(min_point_sigma_px > 0.0) || !(huber_sigmas > 0.0) || !(model_sigma_m >= 0.0) ||
      !(latch_sigma_px >= 0.0) || !(casing_sigma_m >= 0.0) || !(max_edge_scale >= 1.0)) {
    *why =
        "edge noise: point sigma and Huber width > 0, model, latch and casing sigmas >= 0, scale "
        ">= 1";
    return false;
  }
  return true;
}

Eigen::MatrixXd ConsideredUncertainty::Covariance(const PoseParameterisation& parameters) const {
  Eigen::VectorXd sigmas(parameters.considered());
  sigmas.head<3>() << focal_relative, principal_point_px, principal_point_px;
  if (parameters.robot()) sigmas.tail<3>() << height_m, tilt_rad, roll_rad;
  return sigmas.cwiseAbs2().asDiagonal();
}

std::vector<int> ConsideredUncertainty::Estimated(const PoseParameterisation& parameters) const {
  const Eigen::MatrixXd covariance = Covariance(parameters);
  std::vector<int> out;
  for (int i = 0; i < parameters.considered(); ++i) {
    const Handling handling = i < 3 ? intrinsics : mount;
    if (handling == Handling::kEstimate && covariance(i, i) > 0.0) out.push_back(i);
  }
  return out;
}

bool ConsideredUncertainty::Check(std::string* why) const {
  if (!(focal_relative >= 0.0 && focal_relative < 0.5) || !(principal_point_px >= 0.0) ||
      !(height_m >= 0.0) || !(tilt_rad >= 0.0) || !(roll_rad >= 0.0)) {
    *why = "considered uncertainty: sigmas >= 0, focal below 50 %";
    return false;
  }
  return true;
}

bool EdgePoseSolverOptions::Check(std::string* why) const {
  if (!noise.Check(why) || !considered.Check(why)) return false;
  if (iterations < 1 || !(step_tolerance > 0.0) || min_points_per_edge < 2 || min_points < 6) {
    *why = "edge pose solver: >= 1 iteration, tolerance > 0, >= 2 points per edge, >= 6 points";
    return false;
  }
  return true;
}

Eigen::Matrix2d EdgeLevelCovariance(double z_a, double z_b, double focal_px,
                                    const EdgeNoiseOptions& noise) {
  const double ka = focal_px * noise.model_sigma_m / z_a;
  const double kb = focal_px * noise.model_sigma_m / z_b;
  const double latch = noise.latch_sigma_px * noise.latch_sigma_px;
  Eigen::Matrix2d s;
  s << ka * ka + latch, latch, latch, kb * kb + latch;
  return s;
}

Eigen::Vector2d CasingOffsets(const EdgeObservation& edge, const Eigen::Isometry3d& cam_from_world,
                              const CameraIntrinsics& camera) {
  const EdgeLineProjection line(edge.a, edge.b, cam_from_world, camera);
  const Eigen::Vector3d dn = -line.NormalOfTwist().leftCols<3>() * edge.casing_direction;
  const Eigen::Vector2d pa = camera.Project(cam_from_world * edge.a);
  const Eigen::Vector2d pb = camera.Project(cam_from_world * edge.b);
  return {line.At(pa).d_normal.dot(dn), line.At(pb).d_normal.dot(dn)};
}

Eigen::Matrix2d WoodburyKernel(const Eigen::Matrix2d& edge_covariance,
                               const Eigen::Matrix2d& weighted_basis_gram) {
  const Eigen::Matrix2d system =
      Eigen::Matrix2d::Identity() + edge_covariance * weighted_basis_gram;
  const Eigen::Matrix2d kernel = system.inverse() * edge_covariance;
  return 0.5 * (kernel + kernel.transpose());
}

Eigen::MatrixXd ConsiderCovariance(const Eigen::MatrixXd& information,
                                   const Eigen::MatrixXd& coupling,
                                   const Eigen::MatrixXd& considered) {
  const int dof = static_cast<int>(information.rows());
  if (!WellConditioned(information)) {
    return Eigen::MatrixXd::Constant(dof, dof, std::numeric_limits<double>::infinity());
  }
  const Eigen::MatrixXd inverse = information.inverse();
  const Eigen::MatrixXd lean = inverse * coupling;  // d x / d c
  Eigen::MatrixXd covariance = inverse + lean * considered * lean.transpose();
  return 0.5 * (covariance + covariance.transpose());
}

EdgePoseSolution SolveEdgePose(const std::vector<EdgeObservation>& observations,
                               const CameraIntrinsics& camera, const Eigen::Isometry3d& start,
                               const PoseParameterisation& parameters,
                               const EdgePoseSolverOptions& options,
                               const std::vector<bool>& excluded,
                               const std::optional<PosePrior>& prior) {
  EdgePoseSolution out;
  out.parameters = parameters;
  const int dof = parameters.dof();
  out.estimated = options.considered.Estimated(parameters);
  for (int i = 0; i < parameters.considered(); ++i) {
    if (std::find(out.estimated.begin(), out.estimated.end(), i) == out.estimated.end()) {
      out.held.push_back(i);
    }
  }
  out.parameter_deviation = Eigen::VectorXd::Zero(out.estimated.size());
  Eigen::Isometry3d pose = parameters.Apply(start, Eigen::VectorXd::Zero(dof));
  bool converged = false;
  for (int it = 0;; ++it) {
    if (!Assemble(observations, camera, pose, options, excluded, prior, &out)) return out;
    if (!WellConditioned(out.information)) {
      out.reason = "the edges do not fix the pose";
      return out;
    }
    if (converged || it == options.iterations) break;
    const Eigen::VectorXd step = -out.information.ldlt().solve(out.gradient);
    if (!step.allFinite()) {
      out.reason = "the Gauss-Newton step failed";
      return out;
    }
    pose = parameters.Apply(pose, step.head(dof));
    out.parameter_deviation += step.tail(out.estimated.size());
    out.iterations = it + 1;
    converged = step.norm() < options.step_tolerance;
  }
  out.state_covariance = ConsiderCovariance(out.information, out.coupling, out.considered);
  out.covariance = out.state_covariance.topLeftCorner(dof, dof);
  out.ok = out.covariance.allFinite();
  if (!out.ok) out.reason = "the edges do not fix the pose";
  return out;
}

namespace {

// The world twists (6 x indices.size()) of the parameters `indices` (into (s, u0, v0, height,
// tilt, roll)) at the solution's pose: zero for the intrinsics.
Eigen::MatrixXd TwistOfParameters(const EdgePoseSolution& solution,
                                  const std::vector<int>& indices) {
  const Eigen::MatrixXd robot = solution.parameters.TwistOfRobotParameters(solution.cam_from_world);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(6, indices.size());
  for (size_t j = 0; j < indices.size(); ++j) {
    if (indices[j] >= 3) out.col(j) = robot.col(indices[j] - 3);
  }
  return out;
}

}  // namespace

Eigen::MatrixXd TwistOfState(const EdgePoseSolution& solution) {
  Eigen::MatrixXd out(6, solution.state_size());
  out << solution.parameters.TwistOfUnknowns(), TwistOfParameters(solution, solution.estimated);
  return out;
}

Eigen::Matrix<double, 6, 6> WorldTwistCovariance(const EdgePoseSolution& solution) {
  const Eigen::MatrixXd state = TwistOfState(solution);
  Eigen::Matrix<double, 6, 6> covariance = state * solution.state_covariance * state.transpose();
  // The reported pose holds the estimated parameters at nominal: off by -T c^ from the estimate.
  const WorldTwist offset =
      TwistOfParameters(solution, solution.estimated) * solution.parameter_deviation;
  covariance += offset * offset.transpose();
  // The held robot parameters: e_c = -dc, cov(e_z, e_c) = -A^-1 B S_h.
  const Eigen::MatrixXd held = TwistOfParameters(solution, solution.held);
  if (held.isZero()) return covariance;
  const Eigen::MatrixXd cross =
      -solution.information.ldlt().solve(solution.coupling) * solution.considered;
  const Eigen::MatrixXd mixed = state * cross * held.transpose();
  covariance += held * solution.considered * held.transpose() + mixed + mixed.transpose();
  return covariance;
}

}  // namespace linetrack

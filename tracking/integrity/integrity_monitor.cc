#include "tracking/integrity/integrity_monitor.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "models/geometry.h"
#include "models/text_format.h"
#include "tracking/integrity/consistency.h"

namespace linetrack {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kRankTolerance = 1e-9;  // eigenvalues below this share of the largest: no rank

// The position and rotation blocks of the unknowns: (first index, size).
struct Blocks {
  int position_start, position_size, rotation_start, rotation_size;
};
Blocks BlocksOf(const PoseParameterisation& parameters) {
  return parameters.robot() ? Blocks{0, 2, 2, 1} : Blocks{0, 3, 3, 3};
}

double LargestSigma(const Eigen::MatrixXd& block) {
  if (!block.allFinite()) return kInfinity;
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(block).eigenvalues().maxCoeff();
  return std::sqrt(std::max(0.0, largest));
}

// Pseudo-inverse quadratic form v' C^+ v and the rank of C.
double PseudoQuadratic(const Eigen::MatrixXd& covariance, const Eigen::VectorXd& v, int* rank) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(covariance);
  const Eigen::VectorXd values = eigen.eigenvalues();
  const double largest = values.maxCoeff();
  double q = 0.0;
  *rank = 0;
  for (int i = 0; i < values.size(); ++i) {
    if (!(values[i] > kRankTolerance * largest && values[i] > 0.0)) continue;
    ++*rank;
    const double projection = eigen.eigenvectors().col(i).dot(v);
    q += projection * projection / values[i];
  }
  return q;
}

// The multiplier K of a bound K sigma_max that a Gaussian of `dimension` exceeds with
// probability at most `risk`: sqrt(chi2 quantile).
double BoundMultiplier(int dimension, double risk) {
  return std::sqrt(ChiSquareUpperQuantile(dimension, risk));
}

// The multipliers K of the protection levels (section 2.2): I/2 per quantity, of which half to
// the fault-free case (a_ff = I/4) and half to the edges' faults, a_md = (I/4) / (n p); faults
// need no monitoring when n p <= I/4.
struct RiskMultipliers {
  double fault_free_position, fault_free_rotation, missed_position, missed_rotation;
  bool monitor_faults;
};
RiskMultipliers RiskMultipliersOf(const IntegrityOptions& options, const Blocks& b, size_t edges) {
  const double per_quantity = 0.5 * options.integrity_risk;
  const double fault_risk = 0.5 * per_quantity;
  const double fault_prior = options.edge_fault_probability * edges;
  const bool monitor_faults = fault_prior > fault_risk;
  RiskMultipliers k{BoundMultiplier(b.position_size, 0.5 * per_quantity),
                    BoundMultiplier(b.rotation_size, 0.5 * per_quantity), 0.0, 0.0, monitor_faults};
  if (monitor_faults) {
    k.missed_position = BoundMultiplier(b.position_size, fault_risk / fault_prior);
    k.missed_rotation = BoundMultiplier(b.rotation_size, fault_risk / fault_prior);
  }
  return k;
}

// The state of `solution` minus that of `reference`: the unknowns' Difference, then the estimated
// parameters' deviations (the same parameters in both).
Eigen::VectorXd StateDifference(const EdgePoseSolution& solution,
                                const EdgePoseSolution& reference) {
  const int dof = solution.parameters.dof();
  Eigen::VectorXd d(solution.state_size());
  d.head(dof) = solution.parameters.Difference(solution.cam_from_world, reference.cam_from_world);
  d.tail(solution.estimated.size()) = solution.parameter_deviation - reference.parameter_deviation;
  return d;
}

// `solution` without its edge block `index`, downdated at the same linearisation point: the
// information, gradient and coupling of the other edges (and the priors), their covariance.
EdgePoseSolution WithoutEdge(const EdgePoseSolution& solution, int index) {
  EdgePoseSolution out = solution;
  const EdgeBlock& block = solution.edges[index];
  out.information -= block.information;
  out.gradient -= block.gradient;
  out.coupling -= block.coupling;
  out.chi2 -= block.chi2;
  out.points -= block.points;
  out.edges.erase(out.edges.begin() + index);
  out.state_covariance = ConsiderCovariance(out.information, out.coupling, out.considered);
  out.covariance = out.state_covariance.topLeftCorner(out.parameters.dof(), out.parameters.dof());
  out.ok = out.covariance.allFinite();
  return out;
}

// True when some separation test exceeds its chi-square quantile at `risk` (per test).
bool Refuted(const std::vector<EdgeSeparation>& separations, double risk) {
  std::vector<double> thresholds;  // by test_dof, computed when first needed
  for (const EdgeSeparation& s : separations) {
    if (!s.observable || s.test_dof == 0) continue;
    if (static_cast<int>(thresholds.size()) <= s.test_dof) thresholds.resize(s.test_dof + 1, -1.0);
    double& threshold = thresholds[s.test_dof];
    if (threshold < 0.0) threshold = ChiSquareUpperQuantile(s.test_dof, risk);
    if (s.test > threshold) return true;
  }
  return false;
}

// After an exclusion the frame has shown a faulty edge, and faults cluster (a door's jambs latch
// on their casings together): the levels of each pair k, m of the edges left faulty together,
// |x* - x_-km| + K sigma_max(P_-km) (downdated, as SolutionSeparations), K at the faults' share
// I/4 over the pairs' prior C(m, 2) p^2; infinite when the others do not fix the pose.
void PairFaultLevels(const EdgePoseSolution& solution, const IntegrityOptions& options,
                     const Blocks& b, ProtectionLevels* pl) {
  const int m = static_cast<int>(solution.edges.size());
  const double fault_risk = 0.25 * options.integrity_risk;
  const double p = options.edge_fault_probability;
  const double pair_prior = 0.5 * m * (m - 1) * p * p;
  if (!(pair_prior > fault_risk)) return;
  const double k_position = BoundMultiplier(b.position_size, fault_risk / pair_prior);
  const double k_rotation = BoundMultiplier(b.rotation_size, fault_risk / pair_prior);
  const Eigen::MatrixXd& a = solution.information;
  const Eigen::VectorXd optimum_shift = -a.ldlt().solve(solution.gradient);  // x_0* - x_0
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      const EdgeBlock &ei = solution.edges[i], &ej = solution.edges[j];
      const Eigen::MatrixXd reduced = a - ei.information - ej.information;
      const Eigen::MatrixXd covariance = ConsiderCovariance(
          reduced, solution.coupling - ei.coupling - ej.coupling, solution.considered);
      if (!covariance.allFinite()) {
        pl->pair_fault_position_m = pl->pair_fault_rotation_rad = kInfinity;
        return;
      }
      // x_0* - x_km, x_km = x_0 - A''^-1 (g - g_i - g_j).
      const Eigen::VectorXd separation =
          optimum_shift + reduced.ldlt().solve(solution.gradient - ei.gradient - ej.gradient);
      const Eigen::Vector2d sigmas = LargestSigmas(solution.parameters, covariance);
      pl->pair_fault_position_m = std::max(
          pl->pair_fault_position_m,
          separation.segment(b.position_start, b.position_size).norm() + k_position * sigmas[0]);
      pl->pair_fault_rotation_rad = std::max(
          pl->pair_fault_rotation_rad,
          separation.segment(b.rotation_start, b.rotation_size).norm() + k_rotation * sigmas[1]);
    }
  }
}

std::string EdgeName(const std::vector<EdgeObservation>& observations, int k) {
  const int id = observations[k].model_edge >= 0 ? observations[k].model_edge : k;
  return "edge " + std::to_string(id);
}

// `reason` + "; " + part (or part alone).
void Append(std::string* reason, const std::string& part) {
  if (part.empty()) return;
  *reason = reason->empty() ? part : *reason + "; " + part;
}

// log of the Bayes factor N(s; 0, C + B) / N(s; 0, C), in the range of C.
double LogBayesFactor(const Eigen::MatrixXd& c, const Eigen::MatrixXd& b,
                      const Eigen::VectorXd& s) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(c);
  const Eigen::VectorXd values = eigen.eigenvalues();
  std::vector<int> kept;
  for (int i = 0; i < values.size(); ++i) {
    if (values[i] > kRankTolerance * values.maxCoeff() && values[i] > 0.0) kept.push_back(i);
  }
  const int r = static_cast<int>(kept.size());
  if (r == 0) return 0.0;
  Eigen::MatrixXd basis(c.rows(), r);
  Eigen::VectorXd root(r);
  for (int i = 0; i < r; ++i) {
    basis.col(i) = eigen.eigenvectors().col(kept[i]);
    root[i] = std::sqrt(values[kept[i]]);
  }
  // Whitened: s_w = L^-1/2 V' s, B_w = L^-1/2 V' B V L^-1/2; BF = |I + B_w|^-1/2
  // exp(s_w' (I - (I + B_w)^-1) s_w / 2).
  const Eigen::VectorXd s_w = (basis.transpose() * s).cwiseQuotient(root);
  const Eigen::MatrixXd b_w = root.cwiseInverse().asDiagonal() * basis.transpose() * b * basis *
                              root.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd system = Eigen::MatrixXd::Identity(r, r) + b_w;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(system);
  const double log_det = ldlt.vectorD().array().log().sum();
  return -0.5 * log_det + 0.5 * (s_w.squaredNorm() - s_w.dot(ldlt.solve(s_w)));
}

// Widens the levels and the covariance of `out` to bound the error of `start` rather than of the
// solution: |e_start| <= |e_solution| + |start - solution| in position and in rotation angle.
void BoundStartPose(const Eigen::Isometry3d& start, PoseIntegrity* out) {
  const Eigen::Isometry3d& solution = out->solution.cam_from_world;
  const Eigen::Vector3d centre_start = -(start.linear().transpose() * start.translation());
  const Eigen::Vector3d centre_solution = -(solution.linear().transpose() * solution.translation());
  Eigen::Vector3d d_centre = centre_start - centre_solution;
  if (BlocksOf(out->solution.parameters).position_size == 2) d_centre.z() = 0.0;
  const double d_rotation =
      Eigen::AngleAxisd(start.linear() * solution.linear().transpose()).angle();
  out->levels.position_m += d_centre.norm();
  out->levels.start_offset_position_m = d_centre.norm();
  out->levels.rotation_rad += d_rotation;
  out->world_covariance.topLeftCorner<3, 3>() += d_centre * d_centre.transpose();
  out->world_covariance.bottomRightCorner<3, 3>().diagonal().array() += d_rotation * d_rotation;
}

// The status and reason of a solution that passed the fault test.
void Judge(const IntegrityOptions& options, PoseIntegrity* out) {
  const ProtectionLevels& pl = out->levels;
  const bool position_ok = pl.position_m <= options.alert_position_m;
  const bool rotation_ok = pl.rotation_rad <= options.alert_rotation_rad;
  out->status =
      position_ok && rotation_ok ? IntegrityStatus::kTracking : IntegrityStatus::kDegraded;
  if (!std::isfinite(pl.position_m) || !std::isfinite(pl.rotation_rad)) {
    Append(&out->reason, std::isfinite(pl.pair_fault_position_m)
                             ? "a fault of one edge would go unnoticed"
                             : "after an exclusion, a fault of two more edges would go unnoticed");
    return;
  }
  if (!position_ok) {
    // What sets the level: the fault-free bound or one edge's fault, and the start pose's offset.
    std::string limit =
        pl.limiting_position_edge < 0
            ? "fault-free"
            : "an edge fault; fault-free " + Fixed(pl.fault_free_position_m, 3) + " m";
    const double start = pl.start_offset_position_m;
    if (pl.unrefuted_hypotheses > 0 && pl.wrong_exclusion_position_m + start >= pl.position_m) {
      limit = "the exclusion may be wrong: " + std::to_string(pl.unrefuted_hypotheses) +
              " hypotheses not refuted";
    } else if (pl.pair_fault_position_m > 0.0 &&
               pl.pair_fault_position_m + start >= pl.position_m) {
      limit = "a fault of two more edges after an exclusion";
    }
    Append(&out->reason, "position protection " + Fixed(pl.position_m, 3) + " m > " +
                             Fixed(options.alert_position_m, 3) + " m (" + limit + ", start +" +
                             Fixed(pl.start_offset_position_m, 3) + " m)");
  }
  if (!rotation_ok) {
    Append(&out->reason, "rotation protection " + Fixed(RadToDeg(pl.rotation_rad), 2) + " deg > " +
                             Fixed(RadToDeg(options.alert_rotation_rad), 2) + " deg");
  }
}

}  // namespace

const char* ToString(IntegrityStatus status) {
  switch (status) {
    case IntegrityStatus::kTracking:
      return "tracking";
    case IntegrityStatus::kDegraded:
      return "degraded";
    case IntegrityStatus::kLost:
      return "lost";
  }
  return "lost";
}

bool IntegrityOptions::Check(std::string* why) const {
  if (!solver.Check(why)) return false;
  if (!(alert_position_m > 0.0) || !(alert_rotation_rad > 0.0)) {
    *why = "integrity: alert limits must be positive";
    return false;
  }
  if (!(integrity_risk > 0.0 && integrity_risk < 0.5) ||
      !(false_alarm_probability > 0.0 && false_alarm_probability < 0.5) ||
      !(exclusion_risk > 0.0 && exclusion_risk < 0.5) ||
      !(edge_fault_probability >= 0.0 && edge_fault_probability < 1.0) || !(fault_sigma_px > 0.0)) {
    *why =
        "integrity: risk, false-alarm probability and exclusion risk in (0, 0.5), fault "
        "probability in [0, 1), fault sigma > 0";
    return false;
  }
  if (max_exclusions < 0 || min_edges < 1) {
    *why = "integrity: exclusions >= 0, at least one edge";
    return false;
  }
  return true;
}

Eigen::Vector2d LargestSigmas(const PoseParameterisation& parameters,
                              const Eigen::MatrixXd& covariance) {
  const Blocks b = BlocksOf(parameters);
  return {LargestSigma(covariance.block(b.position_start, b.position_start, b.position_size,
                                        b.position_size)),
          LargestSigma(covariance.block(b.rotation_start, b.rotation_start, b.rotation_size,
                                        b.rotation_size))};
}

std::vector<EdgeSeparation> SolutionSeparations(const EdgePoseSolution& solution,
                                                const IntegrityOptions& options) {
  const Eigen::MatrixXd& a = solution.information;
  const Eigen::MatrixXd a_inverse = a.inverse();
  const Eigen::VectorXd optimum_shift = -a_inverse * solution.gradient;  // x_0* - x_0
  const Eigen::MatrixXd lean = a_inverse * solution.coupling;
  const int edges = static_cast<int>(solution.edges.size());
  std::vector<double> thresholds(a.rows() + 1, -1.0);  // by test_dof, computed when first needed
  std::vector<EdgeSeparation> out;
  for (const EdgeBlock& block : solution.edges) {
    EdgeSeparation s;
    s.observation = block.observation;
    const Eigen::MatrixXd reduced = a - block.information;
    const Eigen::MatrixXd reduced_coupling = solution.coupling - block.coupling;
    s.covariance = ConsiderCovariance(reduced, reduced_coupling, solution.considered);
    s.observable = s.covariance.allFinite();
    if (!s.observable) {
      out.push_back(std::move(s));
      continue;
    }
    const Eigen::MatrixXd reduced_inverse = reduced.inverse();
    // x_k - x_0 = -A'^-1 (g - g_k); separation x_0* - x_k.
    s.separation = optimum_shift + reduced_inverse * (solution.gradient - block.gradient);
    const Eigen::MatrixXd d = reduced_inverse * reduced_coupling - lean;
    s.separation_covariance = reduced_inverse - a_inverse + d * solution.considered * d.transpose();
    s.test = PseudoQuadratic(s.separation_covariance, s.separation, &s.test_dof);
    s.threshold = kInfinity;
    if (s.test_dof > 0) {
      double& threshold = thresholds[std::min<int>(s.test_dof, thresholds.size() - 1)];
      if (threshold < 0.0) {
        threshold = ChiSquareUpperQuantile(s.test_dof, options.false_alarm_probability / edges);
      }
      s.threshold = threshold;
    }
    out.push_back(std::move(s));
  }
  return out;
}

void FaultProbabilities(const EdgePoseSolution& solution, const IntegrityOptions& options,
                        std::vector<EdgeSeparation>* separations) {
  const Eigen::MatrixXd a_inverse = solution.information.inverse();
  const double fault_variance = options.fault_sigma_px * options.fault_sigma_px;
  const double p = std::min(options.edge_fault_probability, 1.0 - 1e-12);
  const double log_odds = p > 0.0 ? std::log(p / (1.0 - p)) : -kInfinity;
  std::vector<double> log_weights(separations->size(), -kInfinity);
  double largest = 0.0;  // the fault-free hypothesis has log weight 0
  for (size_t k = 0; k < separations->size(); ++k) {
    const EdgeSeparation& s = (*separations)[k];
    if (!s.observable) continue;
    const Eigen::MatrixXd shift = a_inverse * solution.edges[k].offset_coupling;
    log_weights[k] =
        log_odds + LogBayesFactor(s.separation_covariance,
                                  fault_variance * shift * shift.transpose(), s.separation);
    largest = std::max(largest, log_weights[k]);
  }
  double total = std::exp(-largest);
  for (double w : log_weights)
    total += std::exp(w - largest);
  for (size_t k = 0; k < separations->size(); ++k)
    (*separations)[k].probability_faulty = std::exp(log_weights[k] - largest) / total;
}

Eigen::MatrixXd FaultAwareCovariance(const EdgePoseSolution& solution,
                                     const std::vector<EdgeSeparation>& separations) {
  Eigen::MatrixXd covariance = solution.state_covariance;
  for (const EdgeSeparation& s : separations) {
    if (!s.observable || !(s.probability_faulty > 0.0)) continue;
    covariance += s.probability_faulty * (s.covariance - solution.state_covariance +
                                          s.separation * s.separation.transpose());
  }
  return covariance;
}

ProtectionLevels ComputeProtectionLevels(const EdgePoseSolution& solution,
                                         const std::vector<EdgeSeparation>& separations,
                                         const IntegrityOptions& options) {
  const Blocks b = BlocksOf(solution.parameters);
  const RiskMultipliers k = RiskMultipliersOf(options, b, separations.size());
  ProtectionLevels pl;
  const Eigen::Vector2d sigmas = LargestSigmas(solution.parameters, solution.covariance);
  pl.fault_free_position_m = k.fault_free_position * sigmas[0];
  pl.fault_free_rotation_rad = k.fault_free_rotation * sigmas[1];
  pl.position_m = pl.fault_free_position_m;
  pl.rotation_rad = pl.fault_free_rotation_rad;
  if (!k.monitor_faults) return pl;
  for (const EdgeSeparation& s : separations) {
    double position = kInfinity, rotation = kInfinity;
    if (s.observable) {
      const Eigen::Vector2d k_sigmas = LargestSigmas(solution.parameters, s.covariance);
      position = s.separation.segment(b.position_start, b.position_size).norm() +
                 k.missed_position * k_sigmas[0];
      rotation = s.separation.segment(b.rotation_start, b.rotation_size).norm() +
                 k.missed_rotation * k_sigmas[1];
    }
    if (position > pl.position_m) {
      pl.position_m = position;
      pl.limiting_position_edge = s.observation;
    }
    if (rotation > pl.rotation_rad) {
      pl.rotation_rad = rotation;
      pl.limiting_rotation_edge = s.observation;
    }
  }
  return pl;
}

ProtectionLevels ExclusionProtectionLevels(const EdgePoseSolution& all_in,
                                           const std::vector<EdgeSeparation>& all_in_separations,
                                           const EdgePoseSolution& solution,
                                           const std::vector<int>& excluded,
                                           const ProtectionLevels& levels,
                                           const IntegrityOptions& options) {
  ProtectionLevels pl = levels;
  if (excluded.empty()) return pl;
  const Blocks b = BlocksOf(solution.parameters);
  const int edges = static_cast<int>(all_in.edges.size());
  const RiskMultipliers k = RiskMultipliersOf(options, b, edges);
  // x - x_0*: the reported state from the all-in optimum (x_0* = x_0 - A^-1 g).
  const Eigen::VectorXd offset =
      StateDifference(solution, all_in) + all_in.information.ldlt().solve(all_in.gradient);
  auto widen = [&](const Eigen::VectorXd& d, const Eigen::MatrixXd& covariance, double k_position,
                   double k_rotation) {
    const Eigen::Vector2d sigmas = LargestSigmas(solution.parameters, covariance);
    pl.wrong_exclusion_position_m =
        std::max(pl.wrong_exclusion_position_m,
                 d.segment(b.position_start, b.position_size).norm() + k_position * sigmas[0]);
    pl.wrong_exclusion_rotation_rad =
        std::max(pl.wrong_exclusion_rotation_rad,
                 d.segment(b.rotation_start, b.rotation_size).norm() + k_rotation * sigmas[1]);
    ++pl.unrefuted_hypotheses;
  };
  // No faulty edge: the all-in tests are chi2 under it; refuted at exclusion_risk / edges each.
  if (!Refuted(all_in_separations, options.exclusion_risk / edges)) {
    widen(offset, all_in.state_covariance, k.fault_free_position, k.fault_free_rotation);
  }
  // Edge j faulty: x_-j is fault-free, and so are the separations of its edges (refuted at
  // exclusion_risk / (n p) shared by its n - 1 tests: the union over the hypotheses).
  const double fault_prior = options.edge_fault_probability * edges;
  const double refutation =
      options.exclusion_risk / std::max(1.0, fault_prior) / std::max(1, edges - 1);
  for (int j = 0; k.monitor_faults && j < edges; ++j) {
    const EdgeSeparation& s = all_in_separations[j];
    // A critical edge: the subset's own levels are unbounded already.
    if (!s.observable) continue;
    if (Refuted(SolutionSeparations(WithoutEdge(all_in, j), options), refutation)) continue;
    widen(offset + s.separation, s.covariance, k.missed_position, k.missed_rotation);
  }
  PairFaultLevels(solution, options, b, &pl);
  const double position = std::max(pl.wrong_exclusion_position_m, pl.pair_fault_position_m);
  if (position > pl.position_m) {
    pl.position_m = position;
    pl.limiting_position_edge = -1;
  }
  pl.rotation_rad =
      std::max({pl.rotation_rad, pl.wrong_exclusion_rotation_rad, pl.pair_fault_rotation_rad});
  return pl;
}

PoseIntegrity EvaluatePoseIntegrity(const std::vector<EdgeObservation>& observations,
                                    const CameraIntrinsics& camera, const Eigen::Isometry3d& start,
                                    const PoseParameterisation& parameters,
                                    const IntegrityOptions& options,
                                    const std::optional<PosePrior>& prior) {
  PoseIntegrity out;
  std::vector<bool> excluded(observations.size(), false);
  Eigen::Isometry3d pose = start;
  std::vector<EdgeSeparation> separations;
  // The all-in solution and its separations, kept when an edge is excluded (a wrong exclusion).
  EdgePoseSolution all_in;
  std::vector<EdgeSeparation> all_in_separations;
  for (int attempt = 0;; ++attempt) {
    out.solution =
        SolveEdgePose(observations, camera, pose, parameters, options.solver, excluded, prior);
    if (out.solution.ok && static_cast<int>(out.solution.edges.size()) < options.min_edges) {
      out.solution.ok = false;
      out.solution.reason = "only " + std::to_string(out.solution.edges.size()) + " edges";
    }
    if (!out.solution.ok) {
      out.status = IntegrityStatus::kLost;
      Append(&out.reason, out.solution.reason);
      return out;
    }
    pose = out.solution.cam_from_world;
    separations = SolutionSeparations(out.solution, options);
    const EdgeSeparation* worst = nullptr;
    out.worst_test_ratio = 0.0;
    for (const EdgeSeparation& s : separations) {
      if (!s.observable || s.test_dof == 0 || !(s.test / s.threshold > out.worst_test_ratio)) {
        continue;
      }
      out.worst_test_ratio = s.test / s.threshold;
      worst = &s;
    }
    if (out.worst_test_ratio <= 1.0) break;
    const std::string fault = EdgeName(observations, worst->observation) + " inconsistent (" +
                              Fixed(worst->test, 1) + " > " + Fixed(worst->threshold, 1) + ")";
    if (attempt == options.max_exclusions) {
      out.status = IntegrityStatus::kLost;
      Append(&out.reason, fault + " after " + std::to_string(attempt) + " exclusions");
      return out;
    }
    if (attempt == 0) {
      all_in = out.solution;
      all_in_separations = separations;
    }
    excluded[worst->observation] = true;
    out.excluded.push_back(worst->observation);
    Append(&out.reason, fault + ", excluded");
  }
  out.levels = ComputeProtectionLevels(out.solution, separations, options);
  out.levels = ExclusionProtectionLevels(all_in, all_in_separations, out.solution, out.excluded,
                                         out.levels, options);
  FaultProbabilities(out.solution, options, &separations);
  const Eigen::MatrixXd state_covariance = FaultAwareCovariance(out.solution, separations);
  out.covariance = state_covariance.topLeftCorner(parameters.dof(), parameters.dof());
  const Eigen::MatrixXd state = TwistOfState(out.solution);
  out.world_covariance =
      WorldTwistCovariance(out.solution) +
      state * (state_covariance - out.solution.state_covariance) * state.transpose();
  const Eigen::Vector2d sigmas = LargestSigmas(parameters, out.covariance);
  out.position_sigma_m = sigmas[0];
  out.rotation_sigma_rad = sigmas[1];
  if (options.bound_start_pose) BoundStartPose(start, &out);
  Judge(options, &out);
  return out;
}

PoseUncertainty UncertaintyOf(const PoseIntegrity& integrity) {
  PoseUncertainty out;
  out.status = integrity.status;
  out.reason = integrity.reason;
  out.excluded_edges = static_cast<int>(integrity.excluded.size());
  if (integrity.status == IntegrityStatus::kLost || !integrity.world_covariance.allFinite()) {
    return out;
  }
  out.world_covariance = integrity.world_covariance;
  const Eigen::Matrix<double, 6, 1> variances = out.world_covariance.diagonal().cwiseMax(0.0);
  out.sigma_x_m = std::sqrt(variances[0]);
  out.sigma_y_m = std::sqrt(variances[1]);
  out.sigma_heading_rad = std::sqrt(variances[5]);
  out.protection_position_m = integrity.levels.position_m;
  out.protection_rotation_rad = integrity.levels.rotation_rad;
  return out;
}

}  // namespace linetrack

// Protection levels and an integrity monitor for a tracked pose, as satellite navigation does it
// (RAIM / ARAIM solution separation; docs/integrity.md, section 2): the pose from all edges is
// compared with the pose without each edge (by downdating the information, not re-solving); a
// separation beyond its own noise means a faulty edge, which is excluded and the pose solved
// again; the protection levels bound the error with the stated integrity risk, also when one
// edge is faulty and not detected.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tracking/integrity/edge_pose_solver.h"

namespace linetrack {

// tracking: the protection levels are within the alert limits; degraded: a pose with its
// covariance that no one should act on blindly; lost: no pose can be trusted.
enum class IntegrityStatus { kTracking, kDegraded, kLost };
const char* ToString(IntegrityStatus status);

struct IntegrityOptions {
  EdgePoseSolverOptions solver;
  // Alert limits (`--alert-limit 0.10,2`): position (metres; horizontal for a robot, the camera
  // centre for a free camera) and rotation (radians; heading for a robot, the rotation angle).
  double alert_position_m = 0.10;
  double alert_rotation_rad = 2.0 * kPi / 180.0;
  // Probability per pose that the error exceeds a protection level unnoticed, shared equally by
  // position and rotation, and in each equally by the fault-free case and the edge faults.
  double integrity_risk = 1e-3;
  // Probability per pose of a fault alarm on fault-free data, shared equally by the edges' tests.
  double false_alarm_probability = 1e-3;
  // Prior probability that a given edge's points are wrong beyond the noise model (latched on an
  // unmodelled line, a model error): door casings and furniture make it common indoors.
  double edge_fault_probability = 0.05;
  // Spread of a fault's offsets at the edge's two ends (pixels, each): the twin line of a door
  // casing a few centimetres away at 2-5 m. Weighs the evidence for a fault (Bayes factor).
  double fault_sigma_px = 3.0;
  // After an exclusion, a hypothesis the exclusion may have got wrong (no faulty edge, or another
  // edge faulty) is dropped from the protection levels only when the separation tests of its
  // fault-free edges fail at this level: the probability per pose of dropping a true one
  // (docs/integrity.md, section 2.3).
  double exclusion_risk = 1e-4;
  int max_exclusions = 2;  // edges the fault test may exclude before the pose is lost
  int min_edges = 3;
  // true: the levels bound the error of the start pose (the tracker's own, which is reported)
  // rather than the solution's: each level grows by the two poses' separation (triangle
  // inequality), and the covariance by its outer product.
  bool bound_start_pose = false;

  bool Check(std::string* why) const;
};

// The pose without one edge, to first order from the full solution, in the solution's state
// (the unknowns and the estimated parameters, whose prior stays): information A' = A - A_k,
// x_k = x_0* - A'^-1 (g - g_k) (x_0* = x_0 - A^-1 g), its covariance (consider parameters
// included), and the separation x_0* - x_k with its fault-free covariance (A'^-1 - A^-1) + D Sc
// D', D = A'^-1 B' - A^-1 B.
struct EdgeSeparation {
  int observation = -1;     // index into the observations
  bool observable = false;  // false: the other edges do not fix the pose
  Eigen::VectorXd separation;
  Eigen::MatrixXd separation_covariance;
  Eigen::MatrixXd covariance;  // of x_k
  double test = 0.0;           // separation' (separation covariance)^+ separation
  int test_dof = 0;            // rank of the separation covariance
  double threshold = 0.0;      // chi2(test_dof) quantile at false_alarm_probability / edges
  // Posterior probability that this edge is the faulty one (FaultProbabilities); 0 when the
  // edge is critical (not observable without it).
  double probability_faulty = 0.0;
};

// The separations of every edge of `solution`.
std::vector<EdgeSeparation> SolutionSeparations(const EdgePoseSolution& solution,
                                                const IntegrityOptions& options);

// Posterior fault probabilities of the edges, written into `separations`: p_k = o BF_k / (1 +
// sum_j o BF_j), o = edge_fault_probability / (1 - edge_fault_probability) the prior odds of one
// faulty edge, BF_k = N(s_k; 0, C_k + G_k F G_k') / N(s_k; 0, C_k) the Bayes factor of the
// separation s_k (covariance C_k) when the edge's end offsets carry a fault b ~ N(0, F), F =
// fault_sigma_px^2 I, which moves the pose by G_k b = A^-1 J_k' S_k^-1 U_k b.
void FaultProbabilities(const EdgePoseSolution& solution, const IntegrityOptions& options,
                        std::vector<EdgeSeparation>* separations);

// The covariance of the reported state averaged over the fault hypotheses (law of total
// covariance, as the matcher's DoubtedCovariance): C + sum_k p_k [(C_k - C) + s_k s_k'], the
// truth being N(x_k, C_k) when edge k is faulty, so that the reported x_0 is off by s_k; C the
// solution's state_covariance.
Eigen::MatrixXd FaultAwareCovariance(const EdgePoseSolution& solution,
                                     const std::vector<EdgeSeparation>& separations);

// Protection levels (metres, radians): the largest of the fault-free bound K_ff sigma_max(P_0)
// and, for each edge, |separation| + K_md sigma_max(P_k), sigma_max the largest axis of the
// position or rotation block, K the square root of the chi-square quantile of the block's
// dimension at the risk allocated (IntegrityOptions). Infinite when an edge's fault could not be
// bounded (the other edges do not fix the pose).
struct ProtectionLevels {
  double position_m = std::numeric_limits<double>::infinity();
  double rotation_rad = std::numeric_limits<double>::infinity();
  double fault_free_position_m = 0.0;
  double fault_free_rotation_rad = 0.0;
  int limiting_position_edge = -1;  // observation whose fault sets the level; -1 fault-free
  // With bound_start_pose: the start pose's distance from the solution, included in the levels.
  double start_offset_position_m = 0.0;
  int limiting_rotation_edge = -1;
  // After an exclusion (ExclusionProtectionLevels): the largest levels of the hypotheses that
  // the exclusion may have got wrong and the data do not refute, and how many there are.
  double wrong_exclusion_position_m = 0.0;
  double wrong_exclusion_rotation_rad = 0.0;
  int unrefuted_hypotheses = 0;
  // After an exclusion: the largest levels of two more edges faulty together (infinite when the
  // others do not fix the pose without them).
  double pair_fault_position_m = 0.0;
  double pair_fault_rotation_rad = 0.0;
};
ProtectionLevels ComputeProtectionLevels(const EdgePoseSolution& solution,
                                         const std::vector<EdgeSeparation>& separations,
                                         const IntegrityOptions& options);

// The protection levels of `solution`, reached from the all-in solution `all_in` by excluding the
// observations `excluded` (docs/integrity.md, section 2.3). A wrong exclusion: each hypothesis h
// of the all-in edges (none faulty: x_h = x_0; edge k faulty: x_h = x_-k) that the separation
// tests of x_h's own edges do not refute at exclusion_risk adds |x - x_h| + K_h sigma_max(P_h).
// More faults: each pair of the edges left adds |x - x_-km| + K sigma_max(P_-km). `levels` (the
// subset's own, ComputeProtectionLevels) only grow; unchanged without an exclusion.
ProtectionLevels ExclusionProtectionLevels(const EdgePoseSolution& all_in,
                                           const std::vector<EdgeSeparation>& all_in_separations,
                                           const EdgePoseSolution& solution,
                                           const std::vector<int>& excluded,
                                           const ProtectionLevels& levels,
                                           const IntegrityOptions& options);

// A tracked pose with its covariance, protection levels and status.
struct PoseIntegrity {
  IntegrityStatus status = IntegrityStatus::kLost;
  std::string reason;  // why degraded or lost, and which edges were excluded
  // The pose (cam_from_world), the fault-free covariance of the unknowns, the noise scales.
  EdgePoseSolution solution;
  // The covariance to report (not when lost): the unknowns' block of FaultAwareCovariance, and the
  // world twist's 6 x 6 (WorldTwistCovariance plus the same fault terms).
  Eigen::MatrixXd covariance;
  Eigen::Matrix<double, 6, 6> world_covariance =
      Eigen::Matrix<double, 6, 6>::Constant(std::numeric_limits<double>::infinity());
  double position_sigma_m = std::numeric_limits<double>::infinity();  // largest axis
  double rotation_sigma_rad = std::numeric_limits<double>::infinity();
  ProtectionLevels levels;
  std::vector<int> excluded;      // observations excluded by the fault test
  double worst_test_ratio = 0.0;  // largest test / threshold of the final solution
};

// The whole monitor: solve (SolveEdgePose), test the separations, exclude the worst edge and
// solve again while a test fails (at most max_exclusions), then the protection levels and the
// status. `prior` (e.g. the odometry's prediction) enters every solution and is never excluded.
PoseIntegrity EvaluatePoseIntegrity(const std::vector<EdgeObservation>& observations,
                                    const CameraIntrinsics& camera, const Eigen::Isometry3d& start,
                                    const PoseParameterisation& parameters,
                                    const IntegrityOptions& options,
                                    const std::optional<PosePrior>& prior = std::nullopt);

// What a frame reports of its pose's integrity (frames.csv, covariance.jsonl): the status and why,
// the 6 x 6 covariance of the world twist (dC, omega; metres, radians; WorldTwist), the standard
// deviations of x, y (world, metres) and heading (omega_z, radians), and the protection levels.
struct PoseUncertainty {
  IntegrityStatus status = IntegrityStatus::kLost;
  std::string reason;
  Eigen::Matrix<double, 6, 6> world_covariance =
      Eigen::Matrix<double, 6, 6>::Constant(std::numeric_limits<double>::infinity());
  double sigma_x_m = std::numeric_limits<double>::infinity();
  double sigma_y_m = std::numeric_limits<double>::infinity();
  double sigma_heading_rad = std::numeric_limits<double>::infinity();
  double protection_position_m = std::numeric_limits<double>::infinity();
  double protection_rotation_rad = std::numeric_limits<double>::infinity();
  int excluded_edges = 0;

  bool has_covariance() const { return world_covariance.allFinite(); }
};

// The report of a monitored pose (infinite sigmas and levels when lost).
PoseUncertainty UncertaintyOf(const PoseIntegrity& integrity);

// Largest standard deviation of the position and rotation blocks of a covariance of the unknowns
// (robot: x, y | heading; free: C | omega).
Eigen::Vector2d LargestSigmas(const PoseParameterisation& parameters,
                              const Eigen::MatrixXd& covariance);

}  // namespace linetrack

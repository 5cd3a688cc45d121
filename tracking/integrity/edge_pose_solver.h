// A tracked pose and its covariance from the refinement's edge points, honest about what the
// edges cannot see (docs/integrity.md, section 1): the points of one model edge share an error
// (the model is a few millimetres off, a blurred or neighbouring line pulls the moving edges), so
// each edge's residuals r = J dx + U beta + n are whitened together (Woodbury, 2 x 2 per edge);
// the intrinsics and a robot's height, tilt and roll are estimated with the pose under their
// stated prior, or held at nominal as consider parameters.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "tracking/integrity/edge_residual.h"

namespace linetrack {

// The noise of the edge points.
struct EdgeNoiseOptions {
  // The point noise sigma is estimated from the scatter of each edge's points about their own
  // best line (1.4826 x median absolute deviation), at least this (pixels): the sub-pixel locator
  // is not better than about 0.05 px on real images.
  double min_point_sigma_px = 0.05;
  // Points farther than this many sigmas from their edge's own line are down-weighted (Huber).
  double huber_sigmas = 3.0;
  // Edge-level error beta = (offset at end a, offset at end b), pixels along the normal, with
  // covariance diag((f s_m / Z_a)^2, (f s_m / Z_b)^2) + s_l^2 [1 1; 1 1]: s_m the model's
  // position error (metres, each end), Z the depths of the ends, s_l a shift common to the edge
  // (blur, a neighbouring line). "Edges are not where the model says, to a few mm" (issue 14);
  // on the rendered hall (exact model) these values hold the truth inside the 99.9 % region with
  // the median sigma 2.5x the median error (docs/integrity.md, section 4).
  double model_sigma_m = 0.003;
  double latch_sigma_px = 0.2;
  // A frame line's edge (EdgeObservation::casing_direction) may be pulled onto a casing beside
  // it: a shift of the whole edge by c ~ N(0, casing_sigma_m^2) metres along that direction, whose
  // image offsets k c at the two ends (CasingOffsets) add casing_sigma_m^2 k k' to the edge's
  // covariance. Door casings are 5-10 cm wide; the moving edges latch on their outer border
  // (docs/integrity.md section 1.3). 0: frame lines are trusted like face edges.
  double casing_sigma_m = 0.05;
  // The edge-level covariance is scaled by lambda >= 1, chosen so that the median over edges of
  // the edges' own offsets' chi-square matches chi2(2)'s (robust to a faulty edge); at most this.
  bool estimate_edge_scale = true;
  double max_edge_scale = 400.0;

  bool Check(std::string* why) const;
};

// The stated uncertainty of what the solve holds fixed (standard deviations): the calibration
// (`--camera-sigma`) and a robot's height, tilt and roll (encoders, floor). Defaults: a careful
// Zhang calibration of a 640 x 480 camera (0.3 % focal, 1 px centre), a head's encoders and the
// floor (0.1 degree), a measured camera height (5 mm). With a robot, v0 and the tilt cost
// centimetres at a few metres: a floor line's distance moves with the angle below the horizon.
struct ConsideredUncertainty {
  double focal_relative = 0.003;  // of px and py together
  double principal_point_px = 1.0;
  double height_m = 0.005;
  double tilt_rad = 0.1 * kPi / 180.0;
  double roll_rad = 0.1 * kPi / 180.0;

  // What the solve does with a group of these parameters: hold it at nominal and widen the
  // covariance by A^-1 B Sc B' A^-1 (consider), or solve for its deviation from nominal with the
  // pose under the prior N(0, Sc) and report the pose's marginal covariance (estimate), which is
  // never larger (docs/integrity.md, section 1.4).
  enum class Handling { kConsider, kEstimate };
  Handling intrinsics = Handling::kEstimate;  // s, u0, v0
  Handling mount = Handling::kEstimate;       // a robot's height, tilt, roll

  // Diagonal covariance of (s, u0, v0) and, for a robot, (height, tilt, roll).
  Eigen::MatrixXd Covariance(const PoseParameterisation& parameters) const;
  // Indices into (s, u0, v0, height, tilt, roll) of the parameters solved for: those of an
  // estimated group with a sigma above 0 (a zero sigma is an exact value).
  std::vector<int> Estimated(const PoseParameterisation& parameters) const;
  bool Check(std::string* why) const;
};

// A prior on the pose (e.g. the odometry's prediction): mean and covariance in the unknowns of
// the parameterisation; never excluded by the integrity monitor.
struct PosePrior {
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  Eigen::MatrixXd covariance;
};

struct EdgePoseSolverOptions {
  EdgeNoiseOptions noise;
  ConsideredUncertainty considered;
  int iterations = 5;            // Gauss-Newton iterations at most
  double step_tolerance = 1e-7;  // stop when the step (metres, radians) is below this
  int min_points_per_edge = 2;   // edges with fewer points are left out
  int min_points = 12;

  bool Check(std::string* why) const;
};

// One edge's whitened normal-equation terms at the solution, in the state (the unknowns, then
// the estimated parameters' deviations): information A_e = J' S_e^-1 J, gradient g_e =
// J' S_e^-1 r, consider coupling B_e = J' S_e^-1 J_c with the held parameters (S_e the edge's
// residual covariance), chi2_e = r' S_e^-1 r; r, J, J_c at the solution.
struct EdgeBlock {
  int observation = -1;  // index into the solver's input
  int points = 0;
  Eigen::MatrixXd information;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd coupling;
  // J' S_e^-1 U_e (dof x 2): a shift b of the edge's end offsets moves the pose by A^-1 times
  // this times b (the integrity monitor's fault hypotheses).
  Eigen::MatrixXd offset_coupling;
  double chi2 = 0.0;
};

struct EdgePoseSolution {
  bool ok = false;
  std::string reason;  // why not, when !ok
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();
  PoseParameterisation parameters;
  // The state is the unknowns (parameters.dof()) followed by the deviations from nominal of the
  // `estimated` parameters (indices into (s, u0, v0, height, tilt, roll)); `held` are considered.
  // cam_from_world keeps a robot's nominal height, tilt and roll.
  std::vector<int> estimated, held;
  Eigen::VectorXd parameter_deviation;  // the estimated parameters' c^ - c0 (state's tail)
  std::vector<EdgeBlock> edges;
  // Sums of the edges' terms and the priors' (the pose prior's and the estimated parameters'
  // N(0, Sc), which no edge carries, so that downdating an edge never removes them).
  Eigen::MatrixXd information;  // state x state
  Eigen::VectorXd gradient;     // ~0 at the solution
  Eigen::MatrixXd coupling;     // sum of the edges' B_e, state x held
  Eigen::MatrixXd considered;   // covariance of the held parameters
  // A^-1 + A^-1 B Sc B' A^-1 of the state, and its unknowns' block (dof x dof): the marginal.
  Eigen::MatrixXd state_covariance;
  Eigen::MatrixXd covariance;
  double point_sigma_px = 0.0;
  double edge_scale = 1.0;  // lambda
  int points = 0;
  double chi2 = 0.0;  // sum of the edges' chi2_e (and the prior's)
  int iterations = 0;

  int state_size() const { return parameters.dof() + static_cast<int>(estimated.size()); }
};

// The generalised least-squares pose from `observations` (edges and points, undistorted
// `camera`) starting at `start`, skipping the observations flagged in `excluded` (may be empty),
// with the covariance of section 1 of docs/integrity.md. Not ok when too few points remain, the
// information is singular, or an edge falls behind the camera.
EdgePoseSolution SolveEdgePose(const std::vector<EdgeObservation>& observations,
                               const CameraIntrinsics& camera, const Eigen::Isometry3d& start,
                               const PoseParameterisation& parameters,
                               const EdgePoseSolverOptions& options,
                               const std::vector<bool>& excluded = {},
                               const std::optional<PosePrior>& prior = std::nullopt);

// Covariance of the unknowns with the consider parameters: A^-1 + A^-1 B Sc B' A^-1 (the
// estimate moves by A^-1 B dc when the considered parameters are off by dc). Infinite entries
// when A is singular.
Eigen::MatrixXd ConsiderCovariance(const Eigen::MatrixXd& information,
                                   const Eigen::MatrixXd& coupling,
                                   const Eigen::MatrixXd& considered);

// The covariance (6 x 6) of the world twist (dC, omega) of the solution's pose (nominal height,
// tilt and roll): e = T e_z - T c^ - G_h dc_h with T = d twist / d state (TwistOfState), c^ the
// estimated deviations (a known offset: its outer product is added), G_h the held robot
// parameters' twists, cov(e_z, dc_h) = A^-1 B S_h (the estimate leans on the held values).
Eigen::Matrix<double, 6, 6> WorldTwistCovariance(const EdgePoseSolution& solution);

// d (dC, omega) / d state at the solution's pose (6 x state_size()): TwistOfUnknowns, then each
// estimated robot parameter's twist (TwistOfRobotParameters); intrinsics move no pose (zeros).
Eigen::MatrixXd TwistOfState(const EdgePoseSolution& solution);

// The edge-level covariance of one edge in the endpoint basis (pixels^2), for depths z_a, z_b
// (metres) and focal length f (pixels): diag((f s_m / z_a)^2, (f s_m / z_b)^2) + s_l^2 [1 1; 1 1].
Eigen::Matrix2d EdgeLevelCovariance(double z_a, double z_b, double focal_px,
                                    const EdgeNoiseOptions& noise);

// The change of the residuals (pixels) of points at the image of the edge's ends a and b when
// the edge moves by one metre along edge.casing_direction (world), seen from cam_from_world:
// moving the edge by u is moving the camera centre by -u, so the plane normal changes by
// -R [B - A]x u and each end's residual by dr/dn times that (first order).
Eigen::Vector2d CasingOffsets(const EdgeObservation& edge, const Eigen::Isometry3d& cam_from_world,
                              const CameraIntrinsics& camera);

// Whitened information of residuals r = J x + U beta + n, beta ~ N(0, S) and n ~ N(0, D^-1)
// (D diagonal): the inverse covariance D - D U (I + S U'DU)^-1 S U'D (Woodbury; S may be
// singular). Returned as the 2 x 2 kernel G = (I + S M)^-1 S, M = U'DU: J' Sigma^-1 K = J'DK -
// (J'DU) G (U'DK).
Eigen::Matrix2d WoodburyKernel(const Eigen::Matrix2d& edge_covariance,
                               const Eigen::Matrix2d& weighted_basis_gram);

}  // namespace linetrack

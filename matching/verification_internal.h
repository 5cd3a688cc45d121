// Pieces of the verification shared by its source files (verification.cc, edge_candidates.cc,
// hypothesis_trimming.cc, unreported_doubt.cc); not part of the matching library's interface.
#pragma once

#include <limits>
#include <utility>
#include <vector>

#include "matching/line_fit.h"
#include "matching/pose_refinement.h"
#include "matching/quantiles.h"
#include "matching/verification.h"
#include "models/robot_pose.h"

namespace linetrack {

// The full robot pose (known height and tilt) of a 3-DOF pose.
RobotPose Full(const Pose3Dof& pose, const VerificationContext& context);

// The camera with its focal lengths scaled by `scale` (the estimated calibration error).
CameraIntrinsics ScaledCamera(const CameraIntrinsics& camera, double scale);

// A candidate edge seen from the pose: its frustum-clipped image, the clipped world segment, and
// its image line with the derivative w.r.t. (heading, x, y, scale).
struct EdgeImage {
  bool visible = false;
  Segment2 image;
  Segment3 world;
  Eigen::Vector3d line;
  Eigen::Matrix<double, 3, 4> d_line;
  // d image.a / d (heading, x, y, scale) and the same for image.b.
  Eigen::Matrix<double, 2, 4> d_start, d_end;

  // Variances along the image of its two ends for the pose covariance `c`.
  Eigen::Vector2d EndVariance(const Eigen::Matrix4d& c) const {
    const Eigen::Vector2d u = (image.b - image.a).normalized();
    const Eigen::Vector4d ja = d_start.transpose() * u, jb = d_end.transpose() * u;
    return {ja.dot(c * ja), jb.dot(c * jb)};
  }
};

// The edges' images at `pose` over the stretches of them inside the frustum of `seen` (which
// decides visibility and extent; `pose` the position of the image lines).
std::vector<EdgeImage> ProjectEdgesSeenFrom(const VerificationContext& context,
                                            const Pose3Dof& pose, double focal_scale,
                                            const Pose3Dof& seen, double seen_scale);
// The edges' images at `pose`, seen from it.
std::vector<EdgeImage> ProjectEdges(const VerificationContext& context, const Pose3Dof& pose,
                                    double focal_scale);
// ProjectEdges' visibility, pixels and world segments for the edges of `pairs` only, without
// the image lines and their derivatives (the other edges not visible).
std::vector<EdgeImage> ProjectPairedEdges(const VerificationContext& context, const Pose3Dof& pose,
                                          double focal_scale,
                                          const std::vector<std::pair<int, int>>& pairs);

// A line that fits an edge within the gates at the pose.
struct Candidate {
  int edge = -1;
  int line = -1;
  LineFit fit;
};

// Every (line, edge) pair within the gates at `pose` (covariance `pose_covariance` of heading,
// x, y, scale), the edge not hidden where the line lies (seen from `seen` when given, of focal
// scale `seen_scale`), and likelier than clutter (any finite ratio when `any_ratio`).
std::vector<Candidate> Candidates(const VerificationContext& context,
                                  const std::vector<EdgeImage>& images, const Pose3Dof& pose,
                                  double focal_scale, const Eigen::Matrix4d& pose_covariance,
                                  const LineFitModel& model, bool any_ratio = false,
                                  const Pose3Dof* seen = nullptr, double seen_scale = 1.0);

// Pairs as LineMatches whitened by the noise model with levers from the segment's own middle
// (the projection is not known yet).
std::vector<LineMatch> ToLineMatches(const VerificationContext& context,
                                     const std::vector<std::pair<int, int>>& pairs);

// The verification's refinement options with the prior as bounds (PoseBounds): the prior disk
// and heading interval widened by the options' margins, as the plausibility check widens them.
PoseRefinementOptions RefinementOptions(const VerificationContext& context,
                                        const VerificationOptions& options);

// The explanations of a pair's line at a pose (covariance of heading, x, y, scale; the context's
// gates): the pair's log-likelihood ratio against clutter (nats, also when negative; -infinity
// when outside the gates there), those of its rival explanations (another edge for the line;
// another line for the edge that cannot be a fragment of the same image), and whether the edge
// has such fragments there likelier than clutter. `from` may move visibility, extent and
// occlusion to another pose, give the pair's ratio beyond the gates, and price rival lines that
// other pairs hold.
struct PairExplanations {
  double own = -std::numeric_limits<double>::infinity();
  std::vector<double> rivals;
  bool fragments = false;
};
struct ExplainFrom {
  // When given: the pose (focal scale seen_scale) that decides the edges' visibility, extent
  // (frustum clipping) and occlusion; the image lines and their uncertainty stay at `pose`.
  const Pose3Dof* seen = nullptr;
  double seen_scale = 1.0;
  // The pair's own ratio also beyond the gates (across the line and on its extent).
  bool beyond_gates = false;
  // When given: the interpretation's pairs (edge, line). A rival line that another edge holds
  // there would undo that pair (a line is one edge's image at most): its ratio minus the holder's.
  const std::vector<std::pair<int, int>>* held = nullptr;
};
PairExplanations ExplainPair(const VerificationContext& context, const VerificationOptions& options,
                             const Pose3Dof& pose, double scale, const Eigen::Matrix4d& covariance,
                             const std::pair<int, int>& pair, const ExplainFrom& from = {});

}  // namespace linetrack

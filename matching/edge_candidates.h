// The model edges' images at a pose and the image lines within their gates: the projection
// (with its derivatives w.r.t. heading, x, y and focal scale) and the candidate pairs that guided
// matching, the rival explanations and the doubt of unreported pairs start from.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "matching/line_fit.h"
#include "matching/pose_refinement.h"
#include "matching/verification.h"
#include "models/robot_pose.h"

namespace linetrack {

// The full robot pose (known height and tilt) of a 3-DOF pose, without the context's roll: the
// camera the de-rolled lines are matched in.
RobotPose Full(const Pose3Dof& pose, const VerificationContext& context);

// cam_from_world of the real camera at a 3-DOF pose, with the context's roll: its frustum bounds
// what the image shows.
Eigen::Isometry3d FrustumFromWorld(const Pose3Dof& pose, const VerificationContext& context);

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

// Where Candidates looks for pairs: the pose and focal scale of the edges' image lines, their
// covariance (heading, x, y, scale), the pose that decides occlusion, and which ratios count.
struct CandidateQuery {
  PoseAndScale at;
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  // When set: the pose (and focal scale) from which the edge must not be hidden where the line
  // lies; `at` otherwise.
  std::optional<PoseAndScale> seen;
  // Every pair with a finite log-likelihood ratio, not only those likelier than clutter.
  bool any_ratio = false;
};

// Every (line, edge) pair within the gates of `model` at query.at (the edges' `images` there),
// the edge not hidden where the line lies, and likelier than clutter (any finite ratio when
// query.any_ratio). `stats`, when given, counts the pairs tested (visible edges times lines).
std::vector<Candidate> Candidates(const VerificationContext& context,
                                  const std::vector<EdgeImage>& images, const LineFitModel& model,
                                  const CandidateQuery& query, VerificationStats* stats = nullptr);

}  // namespace linetrack

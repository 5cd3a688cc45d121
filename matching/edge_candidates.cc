#include "matching/edge_candidates.h"

#include <algorithm>
#include <cmath>

namespace linetrack {
namespace {

// d pixel(p) / d (heading, x, y, scale) for the world point p: with X = R (p - C) and
// u = u0 + s px X_x / X_z, v = v0 + s py X_y / X_z.
Eigen::Matrix<double, 2, 4> ProjectionJacobian(const CameraIntrinsics& camera, const PoseView& view,
                                               double scale, const Eigen::Vector3d& p) {
  const Eigen::Vector3d x = view.rotation * (p - view.centre);
  Eigen::Matrix<double, 3, 3> dx;  // columns: d X / d heading, x, y
  dx.col(0) = view.d_rotation * (p - view.centre);
  dx.col(1) = -view.rotation.col(0);
  dx.col(2) = -view.rotation.col(1);
  const double fx = scale * camera.px, fy = scale * camera.py, z2 = x.z() * x.z();
  Eigen::Matrix<double, 2, 4> j;
  for (int k = 0; k < 3; ++k) {
    j(0, k) = fx * (dx(0, k) * x.z() - x.x() * dx(2, k)) / z2;
    j(1, k) = fy * (dx(1, k) * x.z() - x.y() * dx(2, k)) / z2;
  }
  j(0, 3) = camera.px * x.x() / x.z();
  j(1, 3) = camera.py * x.y() / x.z();
  return j;
}

// The point of `edge` seen at the middle of the observed segment: the closest point of the edge
// to the viewing ray through that pixel (world coordinates).
Eigen::Vector3d PointSeenOnEdge(const MatchEdge& edge, const Segment2& observed,
                                const Eigen::Isometry3d& cam_from_world, const Eigen::Vector3d& eye,
                                const CameraIntrinsics& camera) {
  const Eigen::Vector3d ray = cam_from_world.linear().transpose() * camera.Ray(observed.Mid());
  const Eigen::Vector3d w0 = eye - edge.a;
  const Eigen::Vector3d d = edge.b - edge.a;
  const double a = ray.dot(ray), b = ray.dot(d), c = d.dot(d);
  const double p = ray.dot(w0), q = d.dot(w0);
  const double denom = a * c - b * b;
  const double t = denom > 1e-12 ? std::clamp((a * q - b * p) / denom, 0.0, 1.0) : 0.5;
  return edge.a + t * d;
}

// The image of `edge` (world segment, pixels, visible) over its stretch inside the frustum of
// the seen camera, placed by the camera at `cam_from_world`; false when not visible.
bool ClippedImage(const MatchEdge& edge, const Eigen::Isometry3d& cam_from_world,
                  const CameraIntrinsics& camera, const Eigen::Isometry3d& seen_from_world,
                  const CameraIntrinsics& seen_camera, EdgeImage* image) {
  image->world = {edge.a, edge.b};
  if (!ClipToFrustum(seen_from_world, seen_camera, 0.05, &image->world)) return false;
  const Eigen::Vector3d a = cam_from_world * image->world.a, b = cam_from_world * image->world.b;
  if (!(a.z() > 0.05 && b.z() > 0.05)) return false;  // behind the camera at `pose`
  image->image = {camera.Project(a), camera.Project(b)};
  if (image->image.Length() < 1e-6) return false;
  image->visible = true;
  return true;
}

}  // namespace

RobotPose Full(const Pose3Dof& pose, const VerificationContext& context) {
  return {pose.x, pose.y, pose.heading, context.height, context.tilt};
}

Eigen::Isometry3d FrustumFromWorld(const Pose3Dof& pose, const VerificationContext& context) {
  RobotPose rolled = Full(pose, context);
  rolled.roll = context.roll;
  return CamFromWorld(rolled);
}

CameraIntrinsics ScaledCamera(const CameraIntrinsics& camera, double scale) {
  CameraIntrinsics c = camera;
  c.px *= scale;
  c.py *= scale;
  return c;
}

std::vector<EdgeImage> ProjectEdgesSeenFrom(const VerificationContext& context,
                                            const Pose3Dof& pose, double focal_scale,
                                            const Pose3Dof& seen, double seen_scale) {
  const CameraIntrinsics camera = ScaledCamera(*context.camera, focal_scale);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(pose, context));
  const CameraIntrinsics seen_camera = ScaledCamera(*context.camera, seen_scale);
  const Eigen::Isometry3d seen_from_world = FrustumFromWorld(seen, context);
  const PoseView view = ViewOf(pose, context.height, context.tilt);
  std::vector<EdgeImage> out(context.edges->size());
  for (size_t e = 0; e < out.size(); ++e) {
    const MatchEdge& edge = (*context.edges)[e];
    EdgeImage& image = out[e];
    if (!ClippedImage(edge, cam_from_world, camera, seen_from_world, seen_camera, &image)) continue;
    image.line =
        ProjectedEdgeLine(edge.a, edge.b, *context.camera, view, focal_scale, &image.d_line);
    image.d_start = ProjectionJacobian(*context.camera, view, focal_scale, image.world.a);
    image.d_end = ProjectionJacobian(*context.camera, view, focal_scale, image.world.b);
  }
  return out;
}

std::vector<EdgeImage> ProjectEdges(const VerificationContext& context, const Pose3Dof& pose,
                                    double focal_scale) {
  return ProjectEdgesSeenFrom(context, pose, focal_scale, pose, focal_scale);
}

std::vector<EdgeImage> ProjectPairedEdges(const VerificationContext& context, const Pose3Dof& pose,
                                          double focal_scale,
                                          const std::vector<std::pair<int, int>>& pairs) {
  const CameraIntrinsics camera = ScaledCamera(*context.camera, focal_scale);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(pose, context));
  const Eigen::Isometry3d frustum_from_world = FrustumFromWorld(pose, context);
  std::vector<EdgeImage> out(context.edges->size());
  for (const auto& [e, l] : pairs) {
    EdgeImage& image = out.at(static_cast<size_t>(e));
    if (image.visible) continue;  // an edge paired twice
    ClippedImage((*context.edges)[e], cam_from_world, camera, frustum_from_world, camera, &image);
  }
  return out;
}

std::vector<Candidate> Candidates(const VerificationContext& context,
                                  const std::vector<EdgeImage>& images, const LineFitModel& model,
                                  const CandidateQuery& query, VerificationStats* stats) {
  const Eigen::Matrix4d& pose_covariance = query.covariance;
  const bool any_ratio = query.any_ratio;
  const PoseAndScale& viewpoint = query.seen ? *query.seen : query.at;
  const CameraIntrinsics camera = ScaledCamera(*context.camera, viewpoint.focal_scale);
  const Eigen::Isometry3d cam_from_world = CamFromWorld(Full(viewpoint.pose, context));
  const Eigen::Vector3d eye(viewpoint.pose.x, viewpoint.pose.y, context.height);
  std::vector<Candidate> out;
  if (stats != nullptr) {
    const long visible = std::count_if(images.begin(), images.end(),
                                       [](const EdgeImage& image) { return image.visible; });
    stats->pair_tests += visible * static_cast<long>(context.lines->size());
  }
  // Per edge: the ends' variances along the projection, and a distance beyond which no line
  // can be within the gate: chi2 >= max(r_a^2, r_b^2) / trace(covariance), with the trace at most
  // 2 sigma_d^2 + 2 (sigma_theta D)^2 + twice the pose term at the projection's ends.
  std::vector<Eigen::Vector2d> end_variance(images.size());
  std::vector<double> reject_px(images.size(), 0.0);
  const double d = model.image_diagonal_px;
  for (size_t e = 0; e < images.size(); ++e) {
    const EdgeImage& image = images[e];
    if (!image.visible) continue;
    end_variance[e] = image.EndVariance(pose_covariance);
    double pose_variance = 0.0;
    for (const Eigen::Vector2d& end : {image.image.a, image.image.b}) {
      const Eigen::Matrix<double, 1, 4> j =
          Eigen::Vector3d(end.x(), end.y(), 1.0).transpose() * image.d_line;
      pose_variance = std::max(pose_variance, (j * pose_covariance * j.transpose())(0, 0));
    }
    const double trace = 2.0 * model.offset_px * model.offset_px +
                         2.0 * (model.angle_rad * d) * (model.angle_rad * d) + 4.0 * pose_variance;
    reject_px[e] = std::sqrt(model.gate_chi2 * trace);
  }
  for (size_t l = 0; l < context.lines->size(); ++l) {
    const Segment2& observed = (*context.lines)[l].pixels;
    const Eigen::Vector3d qa(observed.a.x(), observed.a.y(), 1.0);
    const Eigen::Vector3d qb(observed.b.x(), observed.b.y(), 1.0);
    for (size_t e = 0; e < images.size(); ++e) {
      const EdgeImage& image = images[e];
      if (!image.visible ||
          std::max(std::abs(image.line.dot(qa)), std::abs(image.line.dot(qb))) > reject_px[e] ||
          context.excluded_pair == std::make_pair(static_cast<int>(e), static_cast<int>(l))) {
        continue;
      }
      Eigen::Matrix<double, 2, 4> j;
      j.row(0) = qa.transpose() * image.d_line;
      j.row(1) = qb.transpose() * image.d_line;
      LineFit fit = FitLine(image.image, observed, j * pose_covariance * j.transpose(), model,
                            end_variance[e]);
      fit.log_likelihood_ratio -= (*context.lines)[l].clutter_log_density;
      if (!fit.gated ||
          !(any_ratio ? std::isfinite(fit.log_likelihood_ratio) : fit.log_likelihood_ratio > 0.0)) {
        continue;
      }
      if (context.occlusion != nullptr &&
          context.occlusion->Blocked(
              eye, PointSeenOnEdge((*context.edges)[e], observed, cam_from_world, eye, camera))) {
        continue;
      }
      out.push_back({static_cast<int>(e), static_cast<int>(l), fit});
    }
  }
  return out;
}

}  // namespace linetrack

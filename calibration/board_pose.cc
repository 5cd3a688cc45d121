#include "calibration/board_pose.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace linetrack {
namespace {

constexpr int kMinPoints = 4;

// IPPE on the normalised undistorted image points (identity camera matrix, no distortion).
bool PlanarPnp(const CameraIntrinsics& camera, const BoardView& view, Eigen::Isometry3d* pose) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < view.board_points.size(); ++i) {
    const Eigen::Vector3d& b = view.board_points[i];
    const Eigen::Vector3d ray = camera.Ray(camera.Undistort(view.image_points[i]));
    object.emplace_back(b.x(), b.y(), b.z());
    image.emplace_back(ray.x(), ray.y());
  }
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, false,
                      cv::SOLVEPNP_IPPE)) {
      return false;
    }
  } catch (const cv::Exception&) {
    return false;
  }
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  cv::cv2eigen(rotation, r);
  cv::cv2eigen(tvec, t);
  pose->linear() = r;
  pose->translation() = t;
  return r.allFinite() && t.allFinite();
}

}  // namespace

PoseResiduals BoardViewResiduals(const CameraIntrinsics& camera, const BoardView& view) {
  return [&camera, &view](const std::vector<Eigen::Isometry3d>& poses, Eigen::VectorXd* r,
                          Eigen::MatrixXd* jacobian) {
    const Eigen::Isometry3d& cam_from_board = poses[0];
    const Eigen::Index n = static_cast<Eigen::Index>(view.board_points.size());
    r->resize(2 * n);
    if (jacobian != nullptr) jacobian->resize(2 * n, 6);
    Eigen::Matrix<double, 2, 3> d_pixel;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d rotated = cam_from_board.linear() * view.board_points[i];
      const Eigen::Vector3d p = rotated + cam_from_board.translation();
      if (!(p.z() > 0.0)) return false;
      r->segment<2>(2 * i) =
          ProjectPoint(camera, p, jacobian ? &d_pixel : nullptr) - view.image_points[i];
      if (jacobian == nullptr) continue;
      // p = R X + t: dp/dshift = I, dp/dw = -[R X]x (R moved to Exp(w) R).
      jacobian->block<2, 3>(2 * i, 0) = d_pixel;
      jacobian->block<2, 3>(2 * i, 3) = -d_pixel * SkewMatrix(rotated);
    }
    return true;
  };
}

BoardPose EstimateBoardPose(const CameraIntrinsics& camera, const BoardView& view,
                            const PoseLeastSquaresOptions& options) {
  BoardPose out;
  if (view.board_points.size() < kMinPoints ||
      view.board_points.size() != view.image_points.size()) {
    out.failure = "fewer than 4 board points";
    return out;
  }
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  if (!PlanarPnp(camera, view, &start)) {
    out.failure = "OpenCV's planar PnP found no pose";
    return out;
  }
  std::vector<Eigen::Isometry3d> poses = {start};
  const PoseLeastSquaresResult solved =
      SolvePoseLeastSquares(BoardViewResiduals(camera, view), options, &poses);
  if (!solved.ok) {
    out.failure = "board pose: " + solved.failure;
    return out;
  }
  out.ok = true;
  out.cam_from_board = poses[0];
  out.rms_px = std::sqrt(solved.cost / static_cast<double>(view.board_points.size()));
  out.covariance = solved.covariance;
  return out;
}

}  // namespace linetrack

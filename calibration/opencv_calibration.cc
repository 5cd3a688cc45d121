#include "calibration/opencv_calibration.h"

#include <opencv2/calib3d.hpp>

#include <cmath>

namespace linetrack {
namespace {

std::vector<cv::Point3f> ToCv(const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3f> out;
  for (const Eigen::Vector3d& p : points)
    out.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                     static_cast<float>(p.z()));
  return out;
}

std::vector<cv::Point2f> ToCv(const std::vector<Eigen::Vector2d>& points) {
  std::vector<cv::Point2f> out;
  for (const Eigen::Vector2d& p : points)
    out.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  return out;
}

cv::Mat CameraMatrix(const OpenCvCalibration& m) {
  return (cv::Mat_<double>(3, 3) << m.fx, 0.0, m.cx, 0.0, m.fy, m.cy, 0.0, 0.0, 1.0);
}

}  // namespace

int OpenCvCalibrationOptions::Flags() const {
  return (fix_aspect_ratio ? cv::CALIB_FIX_ASPECT_RATIO : 0) |
         (zero_tangent ? cv::CALIB_ZERO_TANGENT_DIST : 0) | (fix_k3 ? cv::CALIB_FIX_K3 : 0);
}

OpenCvCalibration CalibrateWithOpenCv(const std::vector<BoardView>& views, int width, int height,
                                      const OpenCvCalibrationOptions& options) {
  OpenCvCalibration result;
  result.flags = options.Flags();
  if (views.size() < 3) {
    result.failure = "OpenCV calibration needs at least 3 views";
    return result;
  }
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (const BoardView& v : views) {
    object_points.push_back(ToCv(v.board_points));
    image_points.push_back(ToCv(v.image_points));
  }
  // With CALIB_FIX_ASPECT_RATIO, calibrateCamera keeps the ratio of the initial fx / fy (1).
  cv::Mat camera = cv::Mat::eye(3, 3, CV_64F);
  cv::Mat distortion = cv::Mat::zeros(5, 1, CV_64F);
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat std_intrinsics, std_extrinsics, per_view;
  try {
    result.rms = cv::calibrateCamera(object_points, image_points, cv::Size(width, height), camera,
                                     distortion, rvecs, tvecs, std_intrinsics, std_extrinsics,
                                     per_view, result.flags);
  } catch (const cv::Exception& e) {
    result.failure = std::string("OpenCV calibration failed: ") + e.what();
    return result;
  }
  result.fx = camera.at<double>(0, 0);
  result.fy = camera.at<double>(1, 1);
  result.cx = camera.at<double>(0, 2);
  result.cy = camera.at<double>(1, 2);
  for (int k = 0; k < 5; ++k)
    result.distortion[static_cast<size_t>(k)] = distortion.at<double>(k);
  for (int k = 0; k < 9 && k < std_intrinsics.rows; ++k)
    result.std_dev[static_cast<size_t>(k)] = std_intrinsics.at<double>(k);
  for (int v = 0; v < per_view.rows; ++v)
    result.view_error.push_back(per_view.at<double>(v));
  for (size_t v = 0; v < rvecs.size(); ++v) {
    result.rotation_vectors.emplace_back(rvecs[v].at<double>(0), rvecs[v].at<double>(1),
                                         rvecs[v].at<double>(2));
    result.translations.emplace_back(tvecs[v].at<double>(0), tvecs[v].at<double>(1),
                                     tvecs[v].at<double>(2));
  }
  const bool finite = std::isfinite(result.fx) && std::isfinite(result.fy) && result.fx > 0.0 &&
                      result.fy > 0.0 && std::isfinite(result.cx) && std::isfinite(result.cy) &&
                      std::isfinite(result.rms);
  if (!finite) {
    result.failure = "OpenCV calibration diverged (non-finite or non-positive focal length)";
    return result;
  }
  result.ok = true;
  return result;
}

std::vector<Eigen::Vector2d> ProjectWithOpenCv(const OpenCvCalibration& model, size_t view,
                                               const std::vector<Eigen::Vector3d>& board_points) {
  std::vector<Eigen::Vector2d> out;
  if (view >= model.rotation_vectors.size() || board_points.empty()) return out;
  const Eigen::Vector3d& r = model.rotation_vectors[view];
  const Eigen::Vector3d& t = model.translations[view];
  const cv::Mat rvec = (cv::Mat_<double>(3, 1) << r.x(), r.y(), r.z());
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(model.distortion.data()));
  std::vector<cv::Point2d> projected;
  std::vector<cv::Point3d> points;
  for (const Eigen::Vector3d& p : board_points)
    points.emplace_back(p.x(), p.y(), p.z());
  cv::projectPoints(points, rvec, tvec, CameraMatrix(model), dist, projected);
  for (const cv::Point2d& p : projected)
    out.emplace_back(p.x, p.y);
  return out;
}

}  // namespace linetrack

#include "app/ros/ros_messages.h"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>

#include "models/errors.h"

namespace linetrack::app {

Eigen::Isometry3d ToIsometry(const geometry_msgs::Pose& pose) {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  Eigen::Quaterniond q(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                       pose.orientation.z);
  if (q.norm() < 1e-9) q = Eigen::Quaterniond::Identity();  // an unset orientation
  iso.linear() = q.normalized().toRotationMatrix();
  iso.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return iso;
}

Eigen::Isometry3d ToIsometry(const geometry_msgs::Transform& transform) {
  geometry_msgs::Pose pose;
  pose.position.x = transform.translation.x;
  pose.position.y = transform.translation.y;
  pose.position.z = transform.translation.z;
  pose.orientation = transform.rotation;
  return ToIsometry(pose);
}

geometry_msgs::Pose ToPoseMsg(const Eigen::Isometry3d& pose) {
  geometry_msgs::Pose msg;
  const Eigen::Quaterniond q(pose.linear());
  msg.position.x = pose.translation().x();
  msg.position.y = pose.translation().y();
  msg.position.z = pose.translation().z();
  msg.orientation.x = q.x();
  msg.orientation.y = q.y();
  msg.orientation.z = q.z();
  msg.orientation.w = q.w();
  return msg;
}

geometry_msgs::Transform ToTransformMsg(const Eigen::Isometry3d& pose) {
  const geometry_msgs::Pose p = ToPoseMsg(pose);
  geometry_msgs::Transform msg;
  msg.translation.x = p.position.x;
  msg.translation.y = p.position.y;
  msg.translation.z = p.position.z;
  msg.rotation = p.orientation;
  return msg;
}

Matrix6d ToMatrix6(const boost::array<double, 36>& values) {
  Matrix6d m;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      m(r, c) = values[static_cast<size_t>(6 * r + c)];
  }
  return m;
}

boost::array<double, 36> ToCovarianceMsg(const Matrix6d& covariance) {
  boost::array<double, 36> values;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c)
      values[static_cast<size_t>(6 * r + c)] = covariance(r, c);
  }
  return values;
}

vpImage<unsigned char> ToGreyImage(const sensor_msgs::ImageConstPtr& msg) {
  cv_bridge::CvImageConstPtr grey;
  try {
    grey = cv_bridge::toCvShare(msg, sensor_msgs::image_encodings::MONO8);
  } catch (const cv_bridge::Exception& e) {
    throw InputError("image encoding '" + msg->encoding + "': " + e.what());
  }
  const cv::Mat& mat = grey->image;
  vpImage<unsigned char> image(static_cast<unsigned>(mat.rows), static_cast<unsigned>(mat.cols));
  for (int r = 0; r < mat.rows; ++r)
    std::memcpy(image[r], mat.ptr<unsigned char>(r), static_cast<size_t>(mat.cols));
  return image;
}

CameraIntrinsics CameraFromInfo(const sensor_msgs::CameraInfo& info) {
  if (info.K[0] <= 0.0 || info.K[4] <= 0.0 || info.width == 0 || info.height == 0) {
    throw InputError("camera_info: no intrinsics (K) or no image size");
  }
  CameraIntrinsics camera;
  camera.name = info.header.frame_id.empty() ? "camera_info" : info.header.frame_id;
  camera.width = static_cast<int>(info.width);
  camera.height = static_cast<int>(info.height);
  camera.px = info.K[0];
  camera.py = info.K[4];
  camera.u0 = info.K[2];
  camera.v0 = info.K[5];
  for (size_t i = 1; i < info.D.size(); ++i) {
    if (std::abs(info.D[i]) > 1e-9) {
      throw InputError("camera_info: distortion '" + info.distortion_model +
                       "' beyond k1 (ViSP's model has one radial term): give --camera");
    }
  }
  const double k1 = info.D.empty() ? 0.0 : info.D[0];
  if (k1 == 0.0) return camera;
  camera.has_distortion = true;
  camera.kud = k1;
  // kdu: least squares of x_u = x_d (1 + kdu r_d^2) over radii up to the image corner, the
  // distorted radius r_d = r_u (1 + k1 r_u^2) of undistorted radii r_u.
  const double corner = std::hypot(std::max(camera.u0, camera.width - camera.u0) / camera.px,
                                   std::max(camera.v0, camera.height - camera.v0) / camera.py);
  double num = 0.0, den = 0.0;
  for (int i = 1; i <= 100; ++i) {
    const double ru = corner * i / 100.0;
    const double rd = ru * (1.0 + k1 * ru * ru);
    num += (ru - rd) * rd * rd * rd;
    den += rd * rd * rd * rd * rd * rd;
  }
  camera.kdu = den > 0.0 ? num / den : -k1;
  return camera;
}

}  // namespace linetrack::app

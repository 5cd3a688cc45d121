// Conversions between ROS messages and linetrack's types: poses (geometry_msgs), the 6 x 6
// covariance (row-major, 36 doubles), images (sensor_msgs/Image through cv_bridge, to 8-bit
// grey) and cameras (sensor_msgs/CameraInfo to ViSP's one-coefficient radial model).
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <boost/array.hpp>

#include "app/ros/ros_geometry.h"
#include "models/camera.h"

namespace linetrack::app {

// A pose or a transform (parent_from_child) as an isometry; an all-zero quaternion is identity.
Eigen::Isometry3d ToIsometry(const geometry_msgs::Pose& pose);
Eigen::Isometry3d ToIsometry(const geometry_msgs::Transform& transform);
geometry_msgs::Pose ToPoseMsg(const Eigen::Isometry3d& pose);
geometry_msgs::Transform ToTransformMsg(const Eigen::Isometry3d& pose);

// Row-major 6 x 6 (geometry_msgs/PoseWithCovariance::covariance) and back.
Matrix6d ToMatrix6(const boost::array<double, 36>& values);
boost::array<double, 36> ToCovarianceMsg(const Matrix6d& covariance);

// An 8-bit grey copy of `msg` (mono8, mono16, bgr8, rgb8, bgra8, rgba8, bayer_*: cv_bridge's
// conversions). Throws InputError naming the encoding when cv_bridge cannot convert it.
vpImage<unsigned char> ToGreyImage(const sensor_msgs::ImageConstPtr& msg);

// The camera of a CameraInfo: K's focal lengths and centre, and ViSP's radial model from a
// plumb_bob (or rational_polynomial) D whose only non-zero coefficient is k1: kud = k1, kdu the
// least-squares inverse over the image. Throws InputError when K is empty or D has other terms
// (ViSP's model cannot represent them: give --camera).
CameraIntrinsics CameraFromInfo(const sensor_msgs::CameraInfo& info);

}  // namespace linetrack::app

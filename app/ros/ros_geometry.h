// The maths between the tracker's camera poses and ROS's frames (REP 103/105): the camera on the
// robot's base, the base's pose in `map`, the map -> odom correction as AMCL publishes it, the
// pose covariance in ROS's convention, odometry interpolated at an image's stamp, and the
// matcher's search bounds from an initial pose's covariance. No ROS types: plain Eigen.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "matching/localizer.h"
#include "models/robot_pose.h"
#include "tracking/head/head_kinematics.h"
#include "tracking/integrity/integrity_monitor.h"
#include "tracking/tracker/relocalizer.h"

namespace linetrack::app {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Where the camera sits on the base (base_link: x forward, y left, z up): its optical centre at
// (x, y, height) metres in the base, turned by `pan` (radians, counter-clockwise from the base's
// x), tilted down by `tilt` (radians) and rolled by `roll` (radians, about the optical axis, the
// image's x towards its y). With a pan-tilt head, pan and tilt are its joint angles; without one,
// pan 0 and the fixed tilt; from TF, all six (MountOfBaseFromCamera).
struct CameraMount {
  double height = 0.0;
  double pan = 0.0;
  double tilt = 0.0;
  double x = 0.0, y = 0.0;  // the optical centre ahead of and left of the base's origin (m)
  double roll = 0.0;

  bool Check(std::string* why) const;
};

// base_from_cam of the mount (ViSP camera axes: x right, y down, z forward): translation
// (x, y, height), rotation CamFromWorldRotation(pan, tilt)^T Rz(roll).
Eigen::Isometry3d BaseFromCamera(const CameraMount& mount);

// The mount of a base_from_cam (the inverse of BaseFromCamera, for |tilt| < 90 degrees): pan and
// tilt from the optical axis f = R e_z (pan = atan2(f_y, f_x), tilt = -asin(f_z)), roll from the
// image's x axis in the level frame of that axis.
CameraMount MountOfBaseFromCamera(const Eigen::Isometry3d& base_from_cam);

// The mount of a camera on a pan-tilt head whose axes cross `crossing_height` metres above the
// base's origin, at joint angles (pan, tilt): the base_from_cam T(0, 0, crossing_height)
// level_from_base Rz(pan) Ry(tilt) tilt_from_camera (head_kinematics.h) read as a CameraMount.
CameraMount MountOnHead(const HeadGeometry& geometry, double crossing_height, double pan,
                        double tilt);

// A planar base pose (x, y, yaw about z) as an isometry of the plane z = 0.
Eigen::Isometry3d PlanarIsometry(const Pose3Dof& pose);

// x, y and yaw of an isometry (yaw of its x axis in the xy plane).
Pose3Dof PlanarOf(const Eigen::Isometry3d& pose);

// The camera's reading for the tracker from the base's planar pose in the map and the mount:
// position of the optical centre (base + Rz(yaw) (x, y)), heading = base yaw + pan, height, tilt
// and roll of the mount.
RobotPose CameraPrior(const Pose3Dof& map_base, const CameraMount& mount);

// map_from_base of a tracked camera: (cam_from_map)^-1 base_from_cam^-1.
Eigen::Isometry3d MapFromBase(const Eigen::Isometry3d& cam_from_map, const CameraMount& mount);

// AMCL's correction: map_from_odom = map_from_base odom_from_base^-1, so that map -> odom ->
// base_link gives the tracked pose at the image's stamp and odometry carries it on after.
Eigen::Isometry3d MapFromOdom(const Eigen::Isometry3d& map_from_base,
                              const Eigen::Isometry3d& odom_from_base);

// ROS's pose covariance (geometry_msgs/PoseWithCovariance: x, y, z, roll, pitch, yaw of the base
// in the map, RosBaseCovariance) of a tracked pose's uncertainty (the integrity monitor's world
// twist covariance, PoseUncertainty), the camera at cam_from_map on `mount`; nullopt without one.
std::optional<Matrix6d> RosCovarianceOf(const PoseUncertainty& uncertainty,
                                        const Eigen::Isometry3d& cam_from_map,
                                        const CameraMount& mount);

// A stamped pose of the base in the odometry frame (nav_msgs/Odometry).
struct StampedOdometry {
  double t = 0.0;  // seconds
  Eigen::Isometry3d odom_from_base = Eigen::Isometry3d::Identity();
};

// The odometry at time t: linear interpolation of the positions and spherical of the rotations
// between the two readings around t; the first or last reading when t is outside their range by
// at most max_gap seconds, else nullopt. `readings` sorted by time.
std::optional<Eigen::Isometry3d> OdometryAt(const std::vector<StampedOdometry>& readings, double t,
                                            double max_gap);

// A pan-tilt head's joint angles (radians) at a stamp (sensor_msgs/JointState).
struct StampedHeadAngles {
  double t = 0.0;  // seconds
  double pan = 0.0, tilt = 0.0;
};

// The head's angles at time t: linear interpolation between the two readings around t; the first
// or last reading when t is outside their range by at most max_gap seconds, else nullopt.
// `readings` sorted by time.
std::optional<StampedHeadAngles> HeadAnglesAt(const std::vector<StampedHeadAngles>& readings,
                                              double t, double max_gap);

// The matcher's first bounds from an initial pose's covariance (RViz's "2D Pose Estimate": 0.25
// m^2 in x and y, 0.0685 rad^2 in yaw): sigma_scale times the largest position and yaw
// standard deviations, clamped to [min, max] (RelocalizationOptions); the defaults give the
// paper's 0.75 m and about 22 degrees for RViz's values.
SearchBounds BoundsFromCovariance(const Matrix6d& covariance, const RelocalizationOptions& limits,
                                  double sigma_scale = 1.5);

}  // namespace linetrack::app

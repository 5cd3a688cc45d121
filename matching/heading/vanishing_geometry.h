// Vanishing-point geometry of a camera with zero roll (docs/heading.md): the image direction
// toward a vanishing point, the consistency of a segment with it, the world vertical in the
// camera frame and the horizontal bearing a segment's interpretation plane contains. Frames:
// camera (ViSP: x right, y down, z forward) and level (tilt undone, y = world down).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

// Unit normal of the interpretation plane of an undistorted segment (camera frame):
// n = ray(a) x ray(b) / |ray(a) x ray(b)|.
Eigen::Vector3d InterpretationNormal(const CameraIntrinsics& camera, const Segment2& segment);

// Image direction (pixels, not normalised) at pixel `uv` toward the vanishing point of the
// camera-frame direction d: the derivative of the projection of ray(uv) + s d at s = 0,
// (px (d_x - x d_z), py (d_y - y d_z)) with (x, y) the normalised coordinates of uv.
Eigen::Vector2d ImageDirectionToward(const CameraIntrinsics& camera, const Eigen::Vector2d& uv,
                                     const Eigen::Vector3d& d);

// Signed angle (radians, in [-pi/2, pi/2]) from the image direction toward d's vanishing point
// at the segment's midpoint to the segment's direction; 0 when the segment can image a line of
// direction d. pi/2 when the midpoint is the vanishing point itself.
double VanishingResidual(const CameraIntrinsics& camera, const Segment2& segment,
                         const Eigen::Vector3d& d);

// The world's down direction (0, 0, -1) in the camera frame at tilt t: (0, cos t, sin t).
Eigen::Vector3d DownInCamera(double tilt);

// The tilt (radians, in (-pi/2, pi/2]) at which a camera-frame vector v is horizontal in the
// world: v . DownInCamera(t) = v_y cos t + v_z sin t = 0. For an interpretation-plane normal,
// the tilt at which the plane contains the vertical (the line can image a vertical edge); for a
// vanishing direction, the tilt at which it is a horizontal direction (its point on the horizon).
double TiltMakingHorizontal(const Eigen::Vector3d& v);

// Bearing alpha (radians, in [0, pi)) of the horizontal direction (sin alpha, 0, cos alpha) that
// the level-frame plane of normal nL contains, measured to the right of the optical axis:
// nL_x sin alpha + nL_z cos alpha = 0.
double HorizontalBearing(const Eigen::Vector3d& normal_level);

// The heading (radians, in [0, pi)) at which a world horizontal direction of angle theta
// (counter-clockwise from +x) is seen at level bearing alpha: h = theta + alpha (mod pi).
double HeadingFromBearing(double theta, double alpha);

// Pixel of the vanishing point of camera-frame direction d (undistorted image); nullopt when d
// is parallel to the image plane (|d_z| below 1e-9 |d|: the point is at infinity).
std::optional<Eigen::Vector2d> VanishingPixel(const CameraIntrinsics& camera,
                                              const Eigen::Vector3d& d);

// Wraps an angle to [0, period).
double WrapPositive(double angle, double period);

// Wraps an angle to [-period / 2, period / 2).
double WrapCentred(double angle, double period);

}  // namespace linetrack

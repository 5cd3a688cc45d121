// Image line segments prepared for matching: interpretation-plane normals in the level frame
// (tilt undone) and their first-order uncertainty from the measurement noise.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

// Measurement noise of image lines (defaults: the paper's Table 1).
struct LineNoise {
  double offset_px = 3.0;        // std of the line's perpendicular offset (pixels)
  double angle_deg = 1.0;        // std of the line's angle about its midpoint (degrees)
  double focal_relative = 0.02;  // std of the relative focal-length error (calibration)
  double tilt_deg = 0.0;         // std of the tilt reading (head encoder)
  // Pieces of one detected line (fragments of an edge's image) lie on one line up to this
  // offset of their endpoints (pixels).
  double fragment_offset_px = 1.0;
  // Share of the clutter lines that image unmodelled vertical structures (furniture legs,
  // poles, stands): they pass through the vertical vanishing point like the images of vertical
  // model edges, so clutter is denser there (1/3 in the synthetic scenes, docs/synth.md).
  double vertical_clutter_fraction = 1.0 / 3.0;
  // A visible model edge gives a line with this probability; a priori this share of the lines
  // of an image are clutter. Together they weigh a line's two explanations: the clutter
  // intensity (clutter_share x lines) against an edge's (detection_probability).
  double detection_probability = 0.9;
  double clutter_share = 0.5;

  bool Check(std::string* why) const;
};

// One image segment, ready for the constraints. Frames: "level" is the camera frame with the
// tilt undone (x right, y down = world -z, z level-forward).
struct ObservedLine {
  int index = -1;   // position in the input list
  Segment2 pixels;  // undistorted pixels
  double length_px = 0.0;
  Eigen::Vector3d ray_a, ray_b;  // level-frame rays through the endpoints (unit)
  Eigen::Vector3d normal;        // level-frame unit normal nL of the interpretation plane
  Eigen::Matrix3d normal_cov;    // covariance of nL (first order)
  // Vertical-edge candidates: |nL_y| is within the noise (the plane contains the vertical).
  bool maybe_vertical = false;
  double bearing = 0.0;        // w: angle of the plane to the right of the optical axis (rad)
  double bearing_sigma = 0.0;  // std of w (rad)
  // ln of the clutter intensity at this line relative to an edge's: the clutter density
  // relative to uniform clutter (offsets over the image diagonal, angles over pi),
  // (1 - f) + f pi / (sqrt(2 pi) sigma_theta) exp(-z^2 / 2) with f the vertical clutter fraction
  // and z = nL_y / std(nL_y) the line's distance to the vertical vanishing point in standard
  // deviations, times clutter_share x lines / detection_probability.
  double clutter_log_density = 0.0;
};

// Prepares the lines for `camera` (undistorted model) at `tilt` (radians). `gate_sigmas` is the
// number of standard deviations for the vertical-candidate test. Throws InputError on NaN or
// zero-length segments (naming the line index).
std::vector<ObservedLine> PrepareLines(const std::vector<Segment2>& lines,
                                       const CameraIntrinsics& camera, double tilt,
                                       const LineNoise& noise, double gate_sigmas);

// Variance of the linear form w . nL for a line (w in level coordinates).
inline double FormVariance(const ObservedLine& line, const Eigen::Vector3d& w) {
  return w.dot(line.normal_cov * w);
}

}  // namespace linetrack

// The steps of EstimateHeading (heading_estimator.h), exposed for tests: segments prepared for
// the vote, the heading accumulator at one tilt, the tilt scan, the assignment of segments to
// the model's directions at a rotation, and the least-squares refinement of that rotation.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "matching/heading/heading_estimator.h"

namespace linetrack {

// A segment ready for the vote (camera frame, undistorted camera).
struct VoteLine {
  int index = -1;  // position in the input list
  Segment2 segment;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // interpretation-plane normal
  // Normals of the segment turned about its midpoint by -+ angle_sigma, and shifted across
  // itself by -+ endpoint_sigma / sqrt(2): the bearing's sensitivity to the segment's noise.
  Eigen::Vector3d turned[2], shifted[2];
  double angle_sigma = 0.0;  // standard deviation of the segment's angle (radians)
  double gate = 0.0;         // largest residual angle of an inlier (radians)
};

// The segments at least options.min_length_px long. Throws InputError on a non-finite segment.
std::vector<VoteLine> PrepareVoteLines(const std::vector<Segment2>& lines,
                                       const CameraIntrinsics& camera,
                                       const HeadingOptions& options);

// True for each vote line whose angle residual to the vertical vanishing point at `tilt` is
// within its gate.
std::vector<bool> VerticalInliers(const std::vector<VoteLine>& lines,
                                  const CameraIntrinsics& camera, double tilt);

// The level-frame horizontal bearing of a vote line at `tilt` (radians, [0, pi)) and its
// standard deviation from the segment's noise.
struct Bearing {
  double alpha = 0.0;
  double sigma = 0.0;
};
Bearing BearingAt(const VoteLine& line, double tilt);

// The log-likelihood ratio ln(1 + c exp(-z^2 / 2)), c = (1 - eps) / eps * period /
// (sqrt(2 pi) sigma), of a measurement z standard deviations from its prediction being an
// inlier (Gaussian, standard deviation sigma) rather than an outlier (uniform over `period`),
// eps the prior outlier probability; and the inlier's posterior probability.
double InlierLogRatio(double z, double sigma, double period, double outlier_probability);
double InlierPosterior(double z, double sigma, double period, double outlier_probability);

// Votes for headings modulo pi at one tilt: bin b covers [b w, (b + 1) w). Each segment that is
// not vertical and whose bearing is certain enough adds InlierLogRatio of the bin's distance to
// theta_k + alpha (the nearest model direction theta_k) in units of the bearing's sigma, within
// gate_sigmas: precise segments vote sharply and strongly, uncertain ones broadly and weakly.
struct HeadingAccumulator {
  double bin_width = 0.0;  // radians
  std::vector<double> scores;

  double Max() const;
  // Centre (radians, [0, pi)) of the first bin holding Max().
  double Peak() const;
  // Sets to zero the bins within `half_width` radians of `heading` (modulo pi).
  void Suppress(double heading, double half_width);
};
HeadingAccumulator VoteHeadings(const std::vector<VoteLine>& lines,
                                const std::vector<bool>& vertical, double tilt,
                                const ModelDirections& directions, const HeadingOptions& options);

// Score of the vertical vanishing point at `tilt`: the sum of InlierLogRatio of the segments'
// angle residuals within their gates (outliers uniform over pi); `vertical` (optional)
// receives the segments within their gates.
double VerticalScore(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                     double tilt, double outlier_probability, std::vector<bool>* vertical);

// The tilt (radians) over the options' range maximising the vertical score plus the best
// heading peak's score, with that score.
struct TiltScan {
  double tilt = 0.0;
  double score = 0.0;
};
TiltScan ScanTilt(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                  const ModelDirections& directions, const HeadingOptions& options);

// Which world direction each vote line points at under (heading, tilt): -1 none, 0 vertical,
// k + 1 model direction k. Vertical wins a tie; horizontal needs a certain bearing.
std::vector<int> AssignLines(const std::vector<VoteLine>& lines, const CameraIntrinsics& camera,
                             double heading, double tilt, const ModelDirections& directions,
                             const HeadingOptions& options);

// Heading and tilt maximising the assigned lines' likelihood under the inlier-outlier mixture:
// iteratively reweighted Gauss-Newton on r_i = VanishingResidual_i / angle_sigma_i, each weighted
// by its inlier posterior (numerical derivatives); the tilt stays fixed unless `estimate_tilt`.
struct RotationFit {
  double heading = 0.0, tilt = 0.0;
  double heading_sigma = 0.0, tilt_sigma = 0.0;  // from the inverse normal matrix, scaled by
                                                 // the reduced chi-square when above 1
  double rms_sigmas = 0.0;  // weighted RMS of the residuals (standard deviations)
  double inliers = 0.0;     // summed inlier posteriors
  int residuals = 0;
};
struct RotationStart {
  double heading = 0.0, tilt = 0.0;
  bool estimate_tilt = false;
};
struct RefinementContext {
  const std::vector<VoteLine>* lines = nullptr;
  const CameraIntrinsics* camera = nullptr;
  const ModelDirections* directions = nullptr;
  int iterations = 10;
  double outlier_probability = 0.5;
};
RotationFit RefineRotation(const RefinementContext& context, const std::vector<int>& assignment,
                           const RotationStart& start);

// World direction of assignment a (0: down, k + 1: model direction k).
Eigen::Vector3d AssignedDirection(int a, const ModelDirections& directions);

}  // namespace linetrack

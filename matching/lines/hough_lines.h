// The paper's line extractor (Ait Aider, Hoppenot, Colle, RAS 2005, section 4.2): Canny edges,
// a Hough transform of the edge pixels in which each pixel votes only for line normals near its
// gradient direction, then the edge pixels along each accumulator peak split into chains, each
// chain approximated by a segment (total least squares).
#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "models/geometry.h"

namespace linetrack {

// Settings of the paper's extractor (defaults set on rendered hall views, docs/lines.md).
struct HoughLineOptions {
  double blur_sigma = 1.0;  // Gaussian smoothing before the gradient (pixels); 0: none
  // Canny hysteresis thresholds on the L2 magnitude of the 3x3 Sobel gradient (a blurred step
  // of h grey levels gives about 2.5 h).
  double canny_low = 20.0, canny_high = 50.0;
  double theta_step_deg = 0.5;          // accumulator resolution of the normal angle
  double orientation_window_deg = 4.0;  // a pixel votes for normals within this of its gradient
  int min_votes = 15;                   // accumulator peaks below this are not examined
  double max_distance_px = 2.0;         // chain pixels lie within this of the peak's line
  double max_gap_px = 4.0;              // a chain breaks where consecutive pixels are farther
  double min_length_px = 15.0;          // shorter chains are dropped
  int max_peaks = 2000;                 // strongest accumulator peaks examined per image

  bool Check(std::string* why) const;
};

// Splits positions along a line (sorted ascending, pixels) into runs whose consecutive
// positions are at most `max_gap` apart; returns [first, last] index pairs of the runs whose
// extent (last - first position) is at least `min_length`.
std::vector<std::pair<int, int>> SplitRuns(const std::vector<double>& positions, double max_gap,
                                           double min_length);

// The detector with its buffers (reused between images of one size). Not thread-safe.
class HoughLineDetector {
 public:
  explicit HoughLineDetector(const HoughLineOptions& options);

  // Segments in pixels of `grey` (CV_8UC1; u = column, pixel centres at integers).
  std::vector<Segment2> Detect(const cv::Mat& grey);

 private:
  struct EdgePixel {
    int x = 0, y = 0;
    float theta_deg = 0.0f;  // gradient direction modulo 180 degrees (the line's normal angle)
  };
  // A local maximum of the accumulator: its votes, normal-angle bin k and offset bin r.
  struct Peak {
    int votes, k, r;
  };
  // Sizes the accumulator and the tables for images of `grey`'s size (kept between images).
  void Resize(const cv::Mat& grey);
  // Canny edges of `grey` into pixels_, with their gradient orientation.
  void FindEdgePixels(const cv::Mat& grey);
  // Fills the accumulator: each edge pixel votes for the normals within the orientation window
  // of its gradient.
  void Vote();
  // Accumulator cell (k, r), theta wrapping with rho mirrored; 0 outside.
  int VotesAt(int k, int r) const;
  // Local maxima of the accumulator with at least min_votes, strongest first, at most max_peaks.
  std::vector<Peak> FindPeaks() const;
  // Edge pixels within `tolerance` of the line (normal angle theta, offset rho from the image
  // centre) and orientation-compatible, ordered along the line.
  void Walk(double theta_deg, double rho, double tolerance, std::vector<int>* hits,
            std::vector<double>* positions);
  void ExtractChains(double theta_deg, double rho, std::vector<Segment2>* segments);
  // The farthest point along `outward` from a segment end reached over edge pixels (any
  // orientation) on the line, gaps of a few pixels allowed.
  Eigen::Vector2d ExtendEnd(const Eigen::Vector2d& end, const Eigen::Vector2d& outward) const;

  HoughLineOptions options_;
  int width_ = 0, height_ = 0;
  cv::Mat smoothed_, dx_, dy_, edges_;
  std::vector<EdgePixel> pixels_;
  std::vector<int> pixel_at_;    // edge pixel index per image pixel, -1 elsewhere
  std::vector<uint8_t> used_;    // per edge pixel: already part of a segment
  std::vector<int> seen_stamp_;  // per edge pixel: last walk that collected it
  int stamp_ = 0;
  std::vector<int> accumulator_;  // theta-major, n_theta x n_rho
  std::vector<double> cos_, sin_;
  int n_theta_ = 0, n_rho_ = 0;
  double rho_max_ = 0.0;
};

}  // namespace linetrack

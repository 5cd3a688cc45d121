#include "matching/lines/hough_lines.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "matching/lines/segment_fitting.h"

namespace linetrack {

bool HoughLineOptions::Check(std::string* why) const {
  auto fail = [why](const char* what) {
    *why = what;
    return false;
  };
  if (!(blur_sigma >= 0.0 && blur_sigma <= 10.0))
    return fail("hough blur_sigma must be in [0, 10]");
  if (!(canny_low > 0.0 && canny_high >= canny_low && std::isfinite(canny_high))) {
    return fail("hough Canny thresholds must satisfy 0 < low <= high");
  }
  if (!(theta_step_deg >= 0.1 && theta_step_deg <= 5.0)) {
    return fail("hough theta_step_deg must be in [0.1, 5]");
  }
  if (!(orientation_window_deg >= 0.0 && orientation_window_deg <= 45.0)) {
    return fail("hough orientation_window_deg must be in [0, 45]");
  }
  if (min_votes < 2) return fail("hough min_votes must be at least 2");
  if (!(max_distance_px >= 0.5 && max_distance_px <= 5.0)) {
    return fail("hough max_distance_px must be in [0.5, 5]");
  }
  if (!(max_gap_px >= 1.0 && max_gap_px <= 50.0))
    return fail("hough max_gap_px must be in [1, 50]");
  if (!(min_length_px >= 2.0 && std::isfinite(min_length_px))) {
    return fail("hough min_length_px must be finite and >= 2");
  }
  if (max_peaks < 1) return fail("hough max_peaks must be at least 1");
  return true;
}

std::vector<std::pair<int, int>> SplitRuns(const std::vector<double>& positions, double max_gap,
                                           double min_length) {
  std::vector<std::pair<int, int>> runs;
  const int n = static_cast<int>(positions.size());
  int first = 0;
  for (int i = 1; i <= n; ++i) {
    if (i < n && positions[i] - positions[i - 1] <= max_gap) continue;
    if (positions[i - 1] - positions[first] >= min_length) runs.emplace_back(first, i - 1);
    first = i;
  }
  return runs;
}

namespace {

// Chain pixels farther than this from the segment fitted to the chain are dropped before the
// final fit (Canny pixels of a straight edge lie within half a pixel of it).
constexpr double kRefitDistancePx = 1.0;
// A chain must have at least this many pixels per pixel of length after the refit.
constexpr double kMinDensity = 0.6;
// At least this share of a chain's pixels must be new (not part of an earlier segment): pixels
// are shared where lines cross, but a chain made of used pixels repeats an earlier line.
constexpr double kMinNewShare = 0.5;
// Ends are extended along the fitted line over edge pixels of any orientation (near a corner
// the gradient turns) within this distance, across gaps up to kExtendGapPx.
constexpr double kExtendDistancePx = 1.0;
constexpr int kExtendGapPx = 2;

double AngleDifferenceMod180(double a, double b) {
  double d = std::abs(a - b);
  d = std::fmod(d, 180.0);
  return std::min(d, 180.0 - d);
}

}  // namespace

HoughLineDetector::HoughLineDetector(const HoughLineOptions& options) : options_(options) {}

void HoughLineDetector::Walk(double theta_deg, double rho, double tolerance, std::vector<int>* hits,
                             std::vector<double>* positions) {
  hits->clear();
  positions->clear();
  ++stamp_;
  const double theta = DegToRad(theta_deg);
  const Eigen::Vector2d normal(std::cos(theta), std::sin(theta));
  const Eigen::Vector2d direction(-normal.y(), normal.x());
  const Eigen::Vector2d centre(0.5 * (width_ - 1), 0.5 * (height_ - 1));
  const Eigen::Vector2d origin = centre + rho * normal;
  // The parameter range of origin + t direction inside the image (slab clipping).
  double t_lo = -1e9, t_hi = 1e9;
  const double lo[2] = {-0.5, -0.5}, hi[2] = {width_ - 0.5, height_ - 0.5};
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(direction[axis]) < 1e-12) {
      if (origin[axis] < lo[axis] || origin[axis] > hi[axis]) return;
      continue;
    }
    double t1 = (lo[axis] - origin[axis]) / direction[axis];
    double t2 = (hi[axis] - origin[axis]) / direction[axis];
    if (t1 > t2) std::swap(t1, t2);
    t_lo = std::max(t_lo, t1);
    t_hi = std::min(t_hi, t2);
  }
  if (t_lo > t_hi) return;
  const int reach = static_cast<int>(std::ceil(tolerance));
  std::vector<std::pair<double, int>> found;
  for (double t = std::ceil(t_lo); t <= t_hi; t += 1.0) {
    const Eigen::Vector2d p = origin + t * direction;
    for (int s = -reach; s <= reach; ++s) {
      const Eigen::Vector2d q = p + s * normal;
      const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
      if (x < 0 || y < 0 || x >= width_ || y >= height_) continue;
      const int index = pixel_at_[static_cast<size_t>(y) * width_ + x];
      if (index < 0 || seen_stamp_[index] == stamp_) continue;
      const Eigen::Vector2d offset(x - origin.x(), y - origin.y());
      if (std::abs(offset.dot(normal)) > tolerance) continue;
      if (AngleDifferenceMod180(pixels_[index].theta_deg, theta_deg) >
          options_.orientation_window_deg) {
        continue;
      }
      seen_stamp_[index] = stamp_;
      found.emplace_back(offset.dot(direction), index);
    }
  }
  std::sort(found.begin(), found.end());
  for (const auto& [position, index] : found) {
    positions->push_back(position);
    hits->push_back(index);
  }
}

Eigen::Vector2d HoughLineDetector::ExtendEnd(const Eigen::Vector2d& end,
                                             const Eigen::Vector2d& outward) const {
  const Eigen::Vector2d d = outward.normalized();
  const Eigen::Vector2d normal(-d.y(), d.x());
  Eigen::Vector2d reached = end;
  int gap = 0;
  for (int step = 1; gap <= kExtendGapPx; ++step) {
    const Eigen::Vector2d p = end + step * d;
    bool hit = false;
    for (int s = -1; s <= 1 && !hit; ++s) {
      const Eigen::Vector2d q = p + s * normal;
      const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
      if (x < 0 || y < 0 || x >= width_ || y >= height_) continue;
      if (pixel_at_[static_cast<size_t>(y) * width_ + x] < 0) continue;
      const Eigen::Vector2d offset(x - end.x(), y - end.y());
      if (std::abs(offset.dot(normal)) > kExtendDistancePx) continue;
      hit = true;
      reached = end + offset.dot(d) * d;
    }
    if (hit) {
      gap = 0;
    } else {
      ++gap;
    }
    if (p.x() < 0 || p.y() < 0 || p.x() > width_ - 1 || p.y() > height_ - 1) break;
  }
  return reached;
}

void HoughLineDetector::ExtractChains(double theta_deg, double rho,
                                      std::vector<Segment2>* segments) {
  std::vector<int> hits;
  std::vector<double> positions;
  Walk(theta_deg, rho, options_.max_distance_px, &hits, &positions);
  const int half_window =
      static_cast<int>(std::floor(options_.orientation_window_deg / options_.theta_step_deg));
  for (const auto& [first, last] :
       SplitRuns(positions, options_.max_gap_px, options_.min_length_px)) {
    std::vector<Eigen::Vector2d> points;
    for (int i = first; i <= last; ++i)
      points.emplace_back(pixels_[hits[i]].x, pixels_[hits[i]].y);
    // Polygonal approximation: fit, drop the pixels off the fitted line, fit again.
    const Segment2 rough = FitSegment(points);
    if (rough.Length() <= 0.0) continue;
    const Eigen::Vector2d d = (rough.b - rough.a).normalized();
    std::vector<Eigen::Vector2d> kept;
    std::vector<int> kept_indices;
    for (int i = first; i <= last; ++i) {
      const Eigen::Vector2d p(pixels_[hits[i]].x, pixels_[hits[i]].y);
      if (std::abs(Cross2(d, p - rough.a)) <= kRefitDistancePx) {
        kept.push_back(p);
        kept_indices.push_back(hits[i]);
      }
    }
    if (kept.size() < 2) continue;
    const int fresh = static_cast<int>(std::count_if(kept_indices.begin(), kept_indices.end(),
                                                     [&](int i) { return used_[i] == 0; }));
    if (fresh < kMinNewShare * kept.size()) continue;
    Segment2 segment = FitSegment(kept);
    const double length = segment.Length();
    if (length < options_.min_length_px || kept.size() < kMinDensity * length) continue;
    segment.a = ExtendEnd(segment.a, segment.a - segment.b);
    segment.b = ExtendEnd(segment.b, segment.b - segment.a);
    segments->push_back(segment);
    // The chain's pixels are explained: withdraw their votes (progressive Hough).
    for (int index : kept_indices) {
      if (used_[index]) continue;
      used_[index] = 1;
      const EdgePixel& px = pixels_[index];
      const int centre_bin = static_cast<int>(std::lround(px.theta_deg / options_.theta_step_deg));
      for (int k = centre_bin - half_window; k <= centre_bin + half_window; ++k) {
        const int kk = (k % n_theta_ + n_theta_) % n_theta_;
        const double r =
            (px.x - 0.5 * (width_ - 1)) * cos_[kk] + (px.y - 0.5 * (height_ - 1)) * sin_[kk];
        const int rb = static_cast<int>(std::lround(r + rho_max_));
        --accumulator_[static_cast<size_t>(kk) * n_rho_ + rb];
      }
    }
  }
}

void HoughLineDetector::Resize(const cv::Mat& grey) {
  if (grey.cols == width_ && grey.rows == height_ && n_theta_ != 0) return;
  width_ = grey.cols;
  height_ = grey.rows;
  n_theta_ = static_cast<int>(std::lround(180.0 / options_.theta_step_deg));
  rho_max_ = std::ceil(0.5 * std::hypot(width_, height_)) + 1.0;
  n_rho_ = 2 * static_cast<int>(rho_max_) + 1;
  cos_.resize(n_theta_);
  sin_.resize(n_theta_);
  for (int k = 0; k < n_theta_; ++k) {
    cos_[k] = std::cos(DegToRad(k * options_.theta_step_deg));
    sin_[k] = std::sin(DegToRad(k * options_.theta_step_deg));
  }
  accumulator_.assign(static_cast<size_t>(n_theta_) * n_rho_, 0);
  pixel_at_.assign(static_cast<size_t>(width_) * height_, -1);
}

void HoughLineDetector::FindEdgePixels(const cv::Mat& grey) {
  if (options_.blur_sigma > 0.0) {
    cv::GaussianBlur(grey, smoothed_, cv::Size(0, 0), options_.blur_sigma);
  } else {
    smoothed_ = grey;
  }
  cv::Sobel(smoothed_, dx_, CV_16S, 1, 0, 3);
  cv::Sobel(smoothed_, dy_, CV_16S, 0, 1, 3);
  cv::Canny(dx_, dy_, edges_, options_.canny_low, options_.canny_high, true);

  // Edge pixels and their gradient orientation (modulo 180 degrees: the line's normal angle).
  pixels_.clear();
  std::fill(pixel_at_.begin(), pixel_at_.end(), -1);
  for (int y = 0; y < height_; ++y) {
    const uint8_t* edge_row = edges_.ptr<uint8_t>(y);
    const int16_t* gx = dx_.ptr<int16_t>(y);
    const int16_t* gy = dy_.ptr<int16_t>(y);
    for (int x = 0; x < width_; ++x) {
      if (edge_row[x] == 0) continue;
      float theta = cv::fastAtan2(gy[x], gx[x]);
      if (theta >= 180.0f) theta -= 180.0f;
      pixel_at_[static_cast<size_t>(y) * width_ + x] = static_cast<int>(pixels_.size());
      pixels_.push_back({x, y, theta});
    }
  }
  used_.assign(pixels_.size(), 0);
  seen_stamp_.assign(pixels_.size(), 0);
  stamp_ = 0;
}

void HoughLineDetector::Vote() {
  std::fill(accumulator_.begin(), accumulator_.end(), 0);
  const int half_window =
      static_cast<int>(std::floor(options_.orientation_window_deg / options_.theta_step_deg));
  const double cx = 0.5 * (width_ - 1), cy = 0.5 * (height_ - 1);
  for (const EdgePixel& px : pixels_) {
    const int centre_bin = static_cast<int>(std::lround(px.theta_deg / options_.theta_step_deg));
    for (int k = centre_bin - half_window; k <= centre_bin + half_window; ++k) {
      const int kk = (k % n_theta_ + n_theta_) % n_theta_;
      const double r = (px.x - cx) * cos_[kk] + (px.y - cy) * sin_[kk];
      ++accumulator_[static_cast<size_t>(kk) * n_rho_ + std::lround(r + rho_max_)];
    }
  }
}

int HoughLineDetector::VotesAt(int k, int r) const {
  if (k < 0 || k >= n_theta_) {
    k = (k + n_theta_) % n_theta_;
    r = n_rho_ - 1 - r;
  }
  if (r < 0 || r >= n_rho_) return 0;
  return accumulator_[static_cast<size_t>(k) * n_rho_ + r];
}

std::vector<HoughLineDetector::Peak> HoughLineDetector::FindPeaks() const {
  std::vector<Peak> peaks;
  for (int k = 0; k < n_theta_; ++k) {
    const int* row = &accumulator_[static_cast<size_t>(k) * n_rho_];
    for (int r = 0; r < n_rho_; ++r) {
      const int v = row[r];
      if (v < options_.min_votes) continue;
      bool is_max = true;
      for (int dk = -1; dk <= 1 && is_max; ++dk) {
        for (int dr = -1; dr <= 1 && is_max; ++dr) {
          if (dk == 0 && dr == 0) continue;
          const int w = VotesAt(k + dk, r + dr);
          // Plateaus: the first cell in scan order wins.
          is_max = v > w || (v == w && (dk > 0 || (dk == 0 && dr > 0)));
        }
      }
      if (is_max) peaks.push_back({v, k, r});
    }
  }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) {
    return a.votes != b.votes ? a.votes > b.votes : (a.k != b.k ? a.k < b.k : a.r < b.r);
  });
  if (static_cast<int>(peaks.size()) > options_.max_peaks) peaks.resize(options_.max_peaks);
  return peaks;
}

std::vector<Segment2> HoughLineDetector::Detect(const cv::Mat& grey) {
  CV_Assert(grey.type() == CV_8UC1 && !grey.empty());
  Resize(grey);
  FindEdgePixels(grey);
  Vote();
  std::vector<Segment2> segments;
  for (const Peak& peak : FindPeaks()) {
    // Votes of pixels already explained by stronger lines have been withdrawn.
    if (accumulator_[static_cast<size_t>(peak.k) * n_rho_ + peak.r] < options_.min_votes) continue;
    ExtractChains(peak.k * options_.theta_step_deg, peak.r - rho_max_, &segments);
  }
  return segments;
}

}  // namespace linetrack

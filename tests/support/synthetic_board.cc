#include "tests/support/synthetic_board.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <mutex>
#include <random>

namespace linetrack {
namespace {

constexpr int kUndistortIterations = 20;
constexpr double kUndistortTolerance2 = 1e-26;  // squared step in normalised units
constexpr int kCharucoPixelsPerSquare = 120;    // texture resolution of a ChArUco board

// Reflectance of the board at (X, Y) metres (board frame), or a negative value off the board.
class BoardTexture {
 public:
  BoardTexture(const PatternSpec& pattern, const BoardRenderOptions& options)
      : pattern_(pattern), options_(options), extent_(BoardExtent(pattern, options)) {
    if (pattern.kind == PatternKind::kCharuco) {
      const auto dictionary =
          cv::aruco::getPredefinedDictionary(ArucoDictionaryId(pattern.dictionary));
      const auto board = cv::aruco::CharucoBoard::create(
          pattern.cols + 1, pattern.rows + 1, static_cast<float>(pattern.square),
          static_cast<float>(pattern.MarkerSide()), dictionary);
      board->draw(cv::Size((pattern.cols + 1) * kCharucoPixelsPerSquare,
                           (pattern.rows + 1) * kCharucoPixelsPerSquare),
                  charuco_, 0, 1);
    }
  }

  double operator()(double x, double y) const {
    if (!extent_.contains(Eigen::Vector2d(x, y))) return -1.0;
    const double s = pattern_.square;
    switch (pattern_.kind) {
      case PatternKind::kChessboard: {
        // Squares span [-s, cols s] x [-s, rows s]; the top-left one is dark.
        if (x < -s || y < -s || x >= pattern_.cols * s || y >= pattern_.rows * s) {
          return options_.white;
        }
        const long i = static_cast<long>(std::floor(x / s)) + 1;
        const long j = static_cast<long>(std::floor(y / s)) + 1;
        return (i + j) % 2 == 0 ? options_.black : options_.white;
      }
      case PatternKind::kCircles: {
        const double cx = std::round(x / s), cy = std::round(y / s);
        if (cx < 0 || cy < 0 || cx >= pattern_.cols || cy >= pattern_.rows) return options_.white;
        const double dx = x - cx * s, dy = y - cy * s;
        const double r = options_.dot_radius * s;
        return dx * dx + dy * dy <= r * r ? options_.black : options_.white;
      }
      case PatternKind::kCharuco: {
        // OpenCV's board image starts at the outer corner, one square before corner (0, 0).
        const double scale = kCharucoPixelsPerSquare / s;
        const int c = static_cast<int>(std::floor((x + s) * scale));
        const int r = static_cast<int>(std::floor((y + s) * scale));
        if (c < 0 || r < 0 || c >= charuco_.cols || r >= charuco_.rows) return options_.white;
        return charuco_.at<unsigned char>(r, c) < 128 ? options_.black : options_.white;
      }
    }
    return -1.0;
  }

 private:
  PatternSpec pattern_;
  BoardRenderOptions options_;
  Eigen::AlignedBox2d extent_;
  cv::Mat charuco_;
};

// Normalised undistorted coordinates of a distorted pixel: solves x_d = x (1 + kud |x|^2).
Eigen::Vector2d UndistortedNormalised(const CameraIntrinsics& camera, double u, double v) {
  const Eigen::Vector2d d((u - camera.u0) / camera.px, (v - camera.v0) / camera.py);
  if (!camera.has_distortion) return d;
  Eigen::Vector2d x = d;
  for (int k = 0; k < kUndistortIterations; ++k) {
    const Eigen::Vector2d next = d / (1.0 + camera.kud * x.squaredNorm());
    const bool converged = (next - x).squaredNorm() < kUndistortTolerance2;
    x = next;
    if (converged) break;
  }
  return x;
}

// Pixel rectangle [u0, u1) x [v0, v1) that holds the board's image: the bounding box of its
// outline's image (64 points per side), grown by a margin; the whole image when part of the
// outline lies behind the camera. Pixels outside it see only the background.
cv::Rect BoardImageBounds(const CameraIntrinsics& camera, const Eigen::Isometry3d& cam_from_board,
                          const Eigen::AlignedBox2d& extent) {
  constexpr int kPerSide = 64;
  constexpr int kMarginPx = 3;
  const cv::Rect whole(0, 0, camera.width, camera.height);
  double u_lo = 1e300, v_lo = 1e300, u_hi = -1e300, v_hi = -1e300;
  const int around[] = {0, 1, 3, 2};  // Eigen's corner ids in order around the box
  for (int side = 0; side < 4; ++side) {
    const Eigen::Vector2d a =
        extent.corner(static_cast<Eigen::AlignedBox2d::CornerType>(around[side]));
    const Eigen::Vector2d b =
        extent.corner(static_cast<Eigen::AlignedBox2d::CornerType>(around[(side + 1) % 4]));
    for (int k = 0; k < kPerSide; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / kPerSide);
      const Eigen::Vector3d q = cam_from_board * Eigen::Vector3d(p.x(), p.y(), 0.0);
      if (!(q.z() > 0.0)) return whole;
      const Eigen::Vector2d uv = camera.Distort(camera.Project(q));
      u_lo = std::min(u_lo, uv.x());
      u_hi = std::max(u_hi, uv.x());
      v_lo = std::min(v_lo, uv.y());
      v_hi = std::max(v_hi, uv.y());
    }
  }
  const cv::Rect box(static_cast<int>(std::floor(u_lo)) - kMarginPx,
                     static_cast<int>(std::floor(v_lo)) - kMarginPx,
                     static_cast<int>(std::ceil(u_hi - u_lo)) + 2 * kMarginPx + 1,
                     static_cast<int>(std::ceil(v_hi - v_lo)) + 2 * kMarginPx + 1);
  return box & whole;
}

using SampleRays = std::vector<Eigen::Vector2d>;

// Normalised undistorted coordinates of the n x n sub-pixel samples of every pixel, in the order
// RenderBoard visits them: ((v * width + u) * n + a) * n + b for pixel (u, v), sample row a and
// column b. They depend on the camera alone, so the views of one camera share one table (the
// last one computed is kept).
std::shared_ptr<const SampleRays> UndistortedSamples(const CameraIntrinsics& camera, int n) {
  static std::mutex mutex;
  static CameraIntrinsics cached_camera;
  static int cached_n = 0;
  static std::shared_ptr<const SampleRays> cached;
  const std::lock_guard<std::mutex> lock(mutex);
  const CameraIntrinsics& c = cached_camera;
  if (cached && cached_n == n && c.width == camera.width && c.height == camera.height &&
      c.px == camera.px && c.py == camera.py && c.u0 == camera.u0 && c.v0 == camera.v0 &&
      c.has_distortion == camera.has_distortion && c.kud == camera.kud) {
    return cached;
  }
  auto rays = std::make_shared<SampleRays>();
  rays->reserve(static_cast<size_t>(camera.width) * camera.height * n * n);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          // Pixel (u, v) covers [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5] (OpenCV's convention).
          const double su = u - 0.5 + (b + 0.5) / n, sv = v - 0.5 + (a + 0.5) / n;
          rays->push_back(UndistortedNormalised(camera, su, sv));
        }
      }
    }
  }
  cached_camera = camera;
  cached_n = n;
  cached = std::move(rays);
  return cached;
}

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

}  // namespace

bool BoardRenderOptions::Check(std::string* why) const {
  if (supersampling < 1 || supersampling > 16) {
    *why = "supersampling must be within [1, 16]";
    return false;
  }
  if (!(blur_sigma >= 0.0) || !(noise_sigma >= 0.0) || !(margin_squares >= 0.0) ||
      !(dot_radius > 0.0 && dot_radius < 0.5)) {
    *why = "blur, noise and margin must be >= 0, the dot radius within (0, 0.5)";
    return false;
  }
  return true;
}

Eigen::AlignedBox2d BoardExtent(const PatternSpec& pattern, const BoardRenderOptions& options) {
  const double s = pattern.square;
  // Chessboard and ChArUco squares reach one square beyond the outer corners; circle grids are
  // framed by one spacing around the outer dots.
  const double m = s * (1.0 + options.margin_squares);
  return Eigen::AlignedBox2d(Eigen::Vector2d(-m, -m), Eigen::Vector2d((pattern.cols - 1) * s + m,
                                                                      (pattern.rows - 1) * s + m));
}

cv::Mat RenderBoard(const PatternSpec& pattern, const CameraIntrinsics& camera,
                    const Eigen::Isometry3d& cam_from_board, const BoardRenderOptions& options) {
  const BoardTexture texture(pattern, options);
  // Board plane: camera point = H (X, Y, 1) with H = [r1 r2 t]; (X, Y, 1) ~ H^-1 (x, y, 1).
  Eigen::Matrix3d h;
  h.col(0) = cam_from_board.linear().col(0);
  h.col(1) = cam_from_board.linear().col(1);
  h.col(2) = cam_from_board.translation();
  const Eigen::Matrix3d board_from_ray = h.inverse();
  const int n = options.supersampling;
  const std::shared_ptr<const SampleRays> rays = UndistortedSamples(camera, n);
  cv::Mat image(camera.height, camera.width, CV_64F, cv::Scalar(options.background));
  const cv::Rect bounds = BoardImageBounds(camera, cam_from_board, BoardExtent(pattern, options));
  for (int v = bounds.y; v < bounds.y + bounds.height; ++v) {
    double* row = image.ptr<double>(v);
    for (int u = bounds.x; u < bounds.x + bounds.width; ++u) {
      const Eigen::Vector2d* x =
          rays->data() + (static_cast<size_t>(v) * camera.width + u) * static_cast<size_t>(n * n);
      double sum = 0.0;
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b, ++x) {
          const Eigen::Vector3d q = board_from_ray * Eigen::Vector3d(x->x(), x->y(), 1.0);
          double value = options.background;
          if (q.z() > 0.0) {  // the ray meets the plane in front of the camera
            const double albedo = texture(q.x() / q.z(), q.y() / q.z());
            if (albedo >= 0.0) value = albedo;
          }
          sum += value;
        }
      }
      row[u] = sum / (n * n);
    }
  }
  if (options.blur_sigma > 0.0) cv::GaussianBlur(image, image, cv::Size(0, 0), options.blur_sigma);
  if (options.noise_sigma > 0.0) {
    cv::Mat noise(image.size(), CV_64F);
    cv::RNG rng(options.seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noise_sigma);
    image += noise;
  }
  cv::Mat out;
  image.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

std::vector<Eigen::Isometry3d> RandomBoardPoses(const PatternSpec& pattern,
                                                const CameraIntrinsics& camera,
                                                const BoardRenderOptions& options, int count,
                                                std::uint64_t seed, double border_px) {
  std::mt19937_64 rng(seed);
  const Eigen::AlignedBox2d extent = BoardExtent(pattern, options);
  const Eigen::Vector2d centre = extent.center();
  // Distance at which the board spans about 40-85 % of the image width.
  const double width_m = extent.sizes().x();
  const double near = camera.px * width_m / (0.85 * camera.width);
  const double far = camera.px * width_m / (0.4 * camera.width);
  std::vector<Eigen::Isometry3d> poses;
  constexpr int kMaxDraws = 100000;
  for (int draw = 0; draw < kMaxDraws && static_cast<int>(poses.size()) < count; ++draw) {
    const double tilt_x = Uniform(rng, -40.0, 40.0) * M_PI / 180.0;
    const double tilt_y = Uniform(rng, -40.0, 40.0) * M_PI / 180.0;
    const double roll = Uniform(rng, -20.0, 20.0) * M_PI / 180.0;
    const double depth = Uniform(rng, near, far);
    const Eigen::Vector2d target(Uniform(rng, 0.3, 0.7) * camera.width,
                                 Uniform(rng, 0.3, 0.7) * camera.height);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
    pose.translation() =
        depth * camera.Ray(target) - pose.linear() * Eigen::Vector3d(centre.x(), centre.y(), 0.0);
    bool inside = true;
    for (int k = 0; k < 4 && inside; ++k) {
      const Eigen::Vector2d corner = extent.corner(static_cast<Eigen::AlignedBox2d::CornerType>(k));
      const Eigen::Vector3d p = pose * Eigen::Vector3d(corner.x(), corner.y(), 0.0);
      if (p.z() <= 0.0) {
        inside = false;
        break;
      }
      const Eigen::Vector2d uv = camera.Distort(camera.Project(p));
      inside = uv.x() >= border_px && uv.y() >= border_px && uv.x() < camera.width - border_px &&
               uv.y() < camera.height - border_px;
    }
    if (inside) poses.push_back(pose);
  }
  return poses;
}

}  // namespace linetrack

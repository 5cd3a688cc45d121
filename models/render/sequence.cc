#include "models/render/sequence.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/render/procedural.h"

namespace linetrack {
namespace {

constexpr double kTangentHalfSpan = 0.2;  // metres each side for the loop's tangent

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + t * d - p).norm();
}

// Every boundary segment the loop keeps away from: outer boundary, holes, walls.
std::vector<Segment2> Obstacles(const NavigableArea& area) {
  std::vector<Segment2> out = area.walls();
  auto add_ring = [&](const Polygon2& ring) {
    for (size_t i = 0; i < ring.vertices.size(); ++i) {
      out.push_back({ring.vertices[i], ring.vertices[(i + 1) % ring.vertices.size()]});
    }
  };
  for (const AreaPart& part : area.parts()) {
    add_ring(part.outer);
    for (const Polygon2& hole : part.holes)
      add_ring(hole);
  }
  return out;
}

// Resamples a closed polyline every `step` along its length.
std::vector<Eigen::Vector2d> ResampleClosed(const std::vector<Eigen::Vector2d>& loop, double step) {
  std::vector<double> cumulative = {0.0};
  for (size_t i = 0; i < loop.size(); ++i) {
    cumulative.push_back(cumulative.back() + (loop[(i + 1) % loop.size()] - loop[i]).norm());
  }
  const double length = cumulative.back();
  const int n = std::max(3, static_cast<int>(std::round(length / step)));
  std::vector<Eigen::Vector2d> out;
  size_t seg = 0;
  for (int k = 0; k < n; ++k) {
    const double s = length * k / n;
    while (seg + 1 < loop.size() && cumulative[seg + 1] < s)
      ++seg;
    const double span = cumulative[seg + 1] - cumulative[seg];
    const double f = span > 0.0 ? (s - cumulative[seg]) / span : 0.0;
    out.push_back(loop[seg] + f * (loop[(seg + 1) % loop.size()] - loop[seg]));
  }
  return out;
}

// Point of a closed, uniformly sampled loop at arc length s (any real s; wraps).
Eigen::Vector2d AtArcLength(const std::vector<Eigen::Vector2d>& loop, double step, double s) {
  const double n = static_cast<double>(loop.size());
  double f = std::fmod(s / step, n);
  if (f < 0.0) f += n;
  const size_t i = static_cast<size_t>(f) % loop.size();
  const double a = f - std::floor(f);
  return (1.0 - a) * loop[i] + a * loop[(i + 1) % loop.size()];
}

// Translation from pose a to pose b expressed in a's frame (x forward, y left).
Eigen::Vector2d RelativeMotion(const Pose3Dof& a, const Pose3Dof& b) {
  const Eigen::Vector2d d(b.x - a.x, b.y - a.y);
  const double c = std::cos(a.heading), s = std::sin(a.heading);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

double LoopLength(const std::vector<Eigen::Vector2d>& loop) {
  double length = 0.0;
  for (size_t i = 0; i < loop.size(); ++i)
    length += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  return length;
}

// Sample position f (in steps) of an open path of `size` points, clamped to its ends: index
// of the segment and fraction along it.
void OpenPathSample(size_t size, double f, size_t* i, double* a) {
  f = std::clamp(f, 0.0, static_cast<double>(size - 1));
  *i = std::min(static_cast<size_t>(f), size - 2);
  *a = f - static_cast<double>(*i);
}

}  // namespace

bool LoopPathOptions::Check(std::string* why) const {
  if (!(wall_distance > 0.0 && wall_distance < 100.0)) {
    *why = "wall_distance must be in (0, 100) metres";
    return false;
  }
  if (!(smoothing >= 0.0 && smoothing < 100.0) || !(step >= 0.005 && step <= 1.0)) {
    *why = "smoothing must be in [0, 100) metres and step in [0.005, 1] metres";
    return false;
  }
  return true;
}

std::vector<Eigen::Vector2d> LoopInsideArea(const NavigableArea& area,
                                            const LoopPathOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(area.source() + ": loop path: " + why);
  const std::vector<Segment2> obstacles = Obstacles(area);
  const Eigen::Vector2d lo = area.BoundsMin(), hi = area.BoundsMax();
  const int cols = static_cast<int>(std::ceil((hi.x() - lo.x()) / options.step)) + 2;
  const int rows = static_cast<int>(std::ceil((hi.y() - lo.y()) / options.step)) + 2;
  if (static_cast<double>(cols) * rows > 2e7) {
    throw InputError(area.source() + ": the navigable area is too large for a loop grid");
  }
  auto cell_centre = [&](double c, double r) {
    return Eigen::Vector2d(lo.x() + (c - 0.5) * options.step, lo.y() + (r - 0.5) * options.step);
  };
  cv::Mat mask(rows, cols, CV_8U, cv::Scalar(0));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d p = cell_centre(c, r);
      if (!area.Contains(p)) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (const Segment2& s : obstacles)
        nearest = std::min(nearest, DistanceToSegment(p, s.a, s.b));
      if (nearest >= options.wall_distance) mask.at<unsigned char>(r, c) = 255;
    }
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  const auto largest = std::max_element(
      contours.begin(), contours.end(),
      [](const auto& a, const auto& b) { return cv::contourArea(a) < cv::contourArea(b); });
  if (largest == contours.end() || largest->size() < 8) {
    throw InputError(area.source() + ": no loop fits " + std::to_string(options.wall_distance) +
                     " m away from the walls");
  }
  std::vector<Eigen::Vector2d> loop;
  for (const cv::Point& p : *largest)
    loop.push_back(cell_centre(p.x, p.y));
  loop = ResampleClosed(loop, options.step);

  // Circular Gaussian smoothing along the loop.
  const double sigma = options.smoothing / options.step;
  const int half = static_cast<int>(std::ceil(3.0 * sigma));
  if (half > 0 && 2 * half + 1 < static_cast<int>(loop.size())) {
    std::vector<double> weights;
    for (int k = -half; k <= half; ++k)
      weights.push_back(std::exp(-0.5 * k * k / (sigma * sigma)));
    std::vector<Eigen::Vector2d> smooth(loop.size(), Eigen::Vector2d::Zero());
    const int n = static_cast<int>(loop.size());
    for (int i = 0; i < n; ++i) {
      double total = 0.0;
      for (int k = -half; k <= half; ++k) {
        smooth[i] += weights[k + half] * loop[((i + k) % n + n) % n];
        total += weights[k + half];
      }
      smooth[i] /= total;
    }
    loop = ResampleClosed(smooth, options.step);
  }
  Polygon2 ring{loop};
  if (ring.SignedArea() < 0.0) std::reverse(loop.begin(), loop.end());
  for (const Eigen::Vector2d& p : loop) {
    if (!area.Contains(p)) {
      throw InputError(area.source() + ": the smoothed loop leaves the navigable area near (" +
                       std::to_string(p.x()) + ", " + std::to_string(p.y()) +
                       "); lower the smoothing or raise the wall distance");
    }
  }
  return loop;
}

bool DriveOptions::Check(std::string* why) const {
  if (!(speed > 0.0 && speed <= 20.0) || !(fps > 0.0 && fps <= 1000.0)) {
    *why = "speed must be in (0, 20] m/s and fps in (0, 1000]";
    return false;
  }
  if (frames < 0 || !(height > 0.0 && height < 100.0)) {
    *why = "frames must be >= 0 and height in (0, 100) metres";
    return false;
  }
  const double limit = DegToRad(89.0);
  if (!(std::abs(tilt) + std::abs(tilt_amplitude) <= limit) || !(std::abs(pan_amplitude) <= kPi)) {
    *why = "|tilt| + |tilt amplitude| must be <= 89 deg and |pan amplitude| <= 180 deg";
    return false;
  }
  if (!(tilt_period > 0.0) || !(pan_period > 0.0)) {
    *why = "pan and tilt periods must be positive (seconds)";
    return false;
  }
  if (!(pan_rate >= 0.0 && pan_rate <= 4.0 * kPi)) {
    *why = "pan rate must be in [0, 720] deg/s";
    return false;
  }
  return true;
}

double HeadPanAt(const DriveOptions& options, double t) {
  if (options.pan_rate > 0.0 && options.pan_amplitude > 0.0) {
    const double period = 4.0 * options.pan_amplitude / options.pan_rate;
    const double phase = t / period - std::floor(t / period);  // [0, 1)
    const double wave = phase < 0.25   ? 4.0 * phase
                        : phase < 0.75 ? 2.0 - 4.0 * phase
                                       : 4.0 * phase - 4.0;
    return options.pan_amplitude * wave;
  }
  return options.pan_amplitude * std::sin(2.0 * kPi * t / options.pan_period);
}

SampledPath SampledPath::Through(std::vector<Eigen::Vector2d> points, bool closed) {
  if (points.size() < 2) throw InputError("path: fewer than two points");
  SampledPath path;
  path.points = std::move(points);
  path.closed = closed;
  path.step = path.Length() / (closed ? path.points.size() : path.points.size() - 1);
  return path;
}

double SampledPath::Length() const {
  if (points.size() < 2) return 0.0;
  if (closed) return LoopLength(points);
  double length = 0.0;
  for (size_t i = 0; i + 1 < points.size(); ++i)
    length += (points[i + 1] - points[i]).norm();
  return length;
}

Eigen::Vector2d SampledPath::PointAt(double s) const {
  if (closed) return AtArcLength(points, step, s);
  size_t i = 0;
  double a = 0.0;
  OpenPathSample(points.size(), s / step, &i, &a);
  return (1.0 - a) * points[i] + a * points[i + 1];
}

double SampledPath::DirectionAt(double s) const {
  const Eigen::Vector2d tangent = PointAt(s + kTangentHalfSpan) - PointAt(s - kTangentHalfSpan);
  return std::atan2(tangent.y(), tangent.x());
}

double SampledPath::HeadingOffsetAt(double s) const {
  const std::vector<HeadingKnot>& k = heading_knots;
  if (k.empty()) return 0.0;
  if (closed) {
    const double length = Length();
    s = std::fmod(s, length);
    if (s < 0.0) s += length;
  }
  if (s <= k.front().s) return k.front().offset;
  if (s >= k.back().s) return k.back().offset;
  const auto next = std::upper_bound(k.begin(), k.end(), s,
                                     [](double v, const HeadingKnot& h) { return v < h.s; });
  const HeadingKnot& a = *(next - 1);
  const HeadingKnot& b = *next;
  return a.offset + (s - a.s) / (b.s - a.s) * (b.offset - a.offset);
}

std::vector<SequenceFrame> DriveAlongLoop(const std::vector<Eigen::Vector2d>& loop,
                                          const DriveOptions& options) {
  return DriveAlongPath(SampledPath::Through(loop, /*closed=*/true), options);
}

std::vector<SequenceFrame> DriveAlongPath(const SampledPath& path, const DriveOptions& options) {
  if (path.points.size() < 2 || !(path.step > 0.0)) {
    throw InputError("path: fewer than two distinct points");
  }
  const double length = path.Length();
  const double per_frame = options.speed / options.fps;
  int frames = options.frames;
  if (frames <= 0) {
    frames = path.closed ? std::max(1, static_cast<int>(length / per_frame))
                         : static_cast<int>(length / per_frame + 1e-9) + 1;
  }
  if (!path.closed && (frames - 1) * per_frame > length + 1e-9) {
    throw InputError("path: it is " + std::to_string(length) + " m long, " +
                     std::to_string(static_cast<int>(length / per_frame + 1e-9) + 1) +
                     " frames at most at this speed and frame rate");
  }
  std::vector<SequenceFrame> out;
  for (int f = 0; f < frames; ++f) {
    SequenceFrame frame;
    frame.t = f / options.fps;
    const double s = f * per_frame;
    const Eigen::Vector2d p = path.PointAt(s);
    double heading = path.DirectionAt(s);
    if (!path.heading_knots.empty()) heading = WrapAngle(heading + path.HeadingOffsetAt(s));
    frame.base = {p.x(), p.y(), heading, options.height, 0.0};
    frame.pan = HeadPanAt(options, frame.t);
    frame.camera = frame.base;
    frame.camera.heading = WrapAngle(frame.base.heading + frame.pan);
    frame.camera.tilt =
        options.tilt + options.tilt_amplitude * std::sin(2.0 * kPi * frame.t / options.tilt_period);
    frame.cam_from_world = CamFromWorld(frame.camera);
    out.push_back(frame);
  }
  return out;
}

std::vector<SequenceFrame> FramesFromTrajectory(const std::vector<StampedPose>& poses) {
  std::vector<SequenceFrame> out;
  for (const StampedPose& pose : poses) {
    SequenceFrame frame;
    frame.t = pose.t;
    frame.cam_from_world = pose.world_from_cam.inverse();
    frame.camera = RobotPoseFromCamFromWorld(frame.cam_from_world);
    frame.base = frame.camera;
    frame.base.tilt = 0.0;
    out.push_back(frame);
  }
  return out;
}

bool OdometryOptions::Check(std::string* why) const {
  for (double v : {distance_noise, heading_noise, heading_walk, scale_bias, heading_bias}) {
    if (!(v >= 0.0 && v < 1.0)) {
      *why = "odometry noise and bias parameters must be in [0, 1)";
      return false;
    }
  }
  if (!(std::abs(scale_error) < 0.5) || !(std::abs(heading_drift) < 1.0)) {
    *why = "the odometry's scale error must be in (-0.5, 0.5) and heading drift in (-1, 1) rad/m";
    return false;
  }
  return true;
}

std::vector<PriorRecord> SimulateOdometryPriors(const std::vector<SequenceFrame>& frames,
                                                const OdometryOptions& options) {
  std::vector<PriorRecord> out;
  if (frames.empty()) return out;
  SeededDraws draws(HashCombine(options.seed, 0x0d0e7e4ull));
  double scale = 1.0 + options.scale_bias * draws.Normal();
  double drift = options.heading_bias * draws.Normal();  // radians per metre
  if (options.scale_error != 0.0) scale += options.scale_error;
  if (options.heading_drift != 0.0) drift += options.heading_drift;
  RobotPose odometry = frames.front().base;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (k > 0) {
      const RobotPose& a = frames[k - 1].base;
      const RobotPose& b = frames[k].base;
      const Eigen::Vector2d delta(b.x - a.x, b.y - a.y);
      const double distance = delta.norm();
      const double turn = WrapAngle(b.heading - a.heading);
      // Direction of travel relative to the mid heading (0 when driving forward).
      const double travel =
          distance > 0.0 ? WrapAngle(std::atan2(delta.y(), delta.x()) - (a.heading + 0.5 * turn))
                         : 0.0;
      const double measured_distance = distance * (scale + options.distance_noise * draws.Normal());
      const double measured_turn = turn * (1.0 + options.heading_noise * draws.Normal()) +
                                   drift * distance +
                                   options.heading_walk * std::sqrt(distance) * draws.Normal();
      const double mid = odometry.heading + 0.5 * measured_turn + travel;
      odometry.x += measured_distance * std::cos(mid);
      odometry.y += measured_distance * std::sin(mid);
      odometry.heading = WrapAngle(odometry.heading + measured_turn);
    }
    PriorRecord record;
    record.t = frames[k].t;
    record.pose = {odometry.x, odometry.y, WrapAngle(odometry.heading + frames[k].pan),
                   frames[k].camera.height, frames[k].camera.tilt};
    out.push_back(record);
  }
  return out;
}

OdometryOptions OdometryForDrift(double drift, uint64_t seed) {
  OdometryOptions options;
  options.seed = seed;
  options.scale_bias = 0.0;
  options.heading_bias = 0.0;
  options.heading_walk = 0.002;
  SeededDraws signs(HashCombine(seed, 0xd21f7ull));
  options.scale_error = (signs.Unit() < 0.5 ? -0.9 : 0.9) * drift;
  options.heading_drift = (signs.Unit() < 0.5 ? -0.02 : 0.02) * drift;
  return options;
}

OdometryDrift MeasureOdometryDrift(const std::vector<SequenceFrame>& frames,
                                   const std::vector<PriorRecord>& priors, double window_m) {
  OdometryDrift out;
  out.window_m = window_m;
  const size_t n = std::min(frames.size(), priors.size());
  if (n < 2) return out;
  std::vector<double> travelled(n, 0.0);  // along the true path
  for (size_t k = 1; k < n; ++k) {
    travelled[k] = travelled[k - 1] + std::hypot(frames[k].base.x - frames[k - 1].base.x,
                                                 frames[k].base.y - frames[k - 1].base.y);
  }
  // Base poses: the prior's heading holds the (exact) head pan.
  auto odometry = [&](size_t k) {
    const RobotPose& p = priors[k].pose;
    return Pose3Dof{p.x, p.y, WrapAngle(p.heading - frames[k].pan)};
  };
  auto truth = [&](size_t k) { return frames[k].base.Planar(); };
  auto relative_error = [&](size_t a, size_t b) {
    const Eigen::Vector2d d_odo = RelativeMotion(odometry(a), odometry(b));
    const Eigen::Vector2d d_true = RelativeMotion(truth(a), truth(b));
    return (d_odo - d_true).norm() / (travelled[b] - travelled[a]);
  };
  if (travelled[n - 1] > 0.0) out.whole_share = relative_error(0, n - 1);
  double sum = 0.0;
  size_t b = 0;
  for (size_t a = 0; a < n; ++a) {
    b = std::max(b, a);
    while (b < n && travelled[b] - travelled[a] < window_m)
      ++b;
    if (b >= n) break;
    const double share = relative_error(a, b);
    out.max_share = std::max(out.max_share, share);
    sum += share;
    ++out.windows;
  }
  out.mean_share = out.windows > 0 ? sum / out.windows : 0.0;
  return out;
}

std::vector<StampedPose> GroundTruthPoses(const std::vector<SequenceFrame>& frames) {
  std::vector<StampedPose> out;
  for (const SequenceFrame& frame : frames)
    out.push_back({frame.t, frame.cam_from_world.inverse()});
  return out;
}

}  // namespace linetrack

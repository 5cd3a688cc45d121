#include "app/replay_output.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/statistics.h"
#include "models/text_format.h"
#include "models/trajectory_io.h"

namespace linetrack::app {

namespace {

nlohmann::ordered_json Percentiles(const std::vector<double>& values) {
  return {{"p50", QuantileNearestRank(values, 0.5)},
          {"p90", QuantileNearestRank(values, 0.9)},
          {"p99", QuantileNearestRank(values, 0.99)},
          {"max", values.empty() ? 0.0 : *std::max_element(values.begin(), values.end())}};
}

nlohmann::ordered_json Statistics(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values)
    sum += v;
  return {{"mean", values.empty() ? 0.0 : sum / values.size()},
          {"median", QuantileNearestRank(values, 0.5)},
          {"max", values.empty() ? 0.0 : *std::max_element(values.begin(), values.end())}};
}

cv::Scalar StatusColour(const FrameReport& report) {
  if (!report.cam_from_world) {
    return report.status == TrackStatus::kInitialising ? cv::Scalar(0, 200, 255)
                                                       : cv::Scalar(0, 0, 255);
  }
  return report.uncertainty.status == IntegrityStatus::kTracking ? cv::Scalar(0, 200, 0)
                                                                 : cv::Scalar(0, 140, 255);
}

void Text(cv::Mat* image, const std::string& text, cv::Point at, cv::Scalar colour) {
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 3, cv::LINE_AA);
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
}

}  // namespace

ReplayLog::ReplayLog(const std::string& dir, bool with_ground_truth, bool all_poses)
    : covariance_(dir), with_ground_truth_(with_ground_truth), all_poses_(all_poses) {
  const std::string poses_path = dir + "/poses.txt", frames_path = dir + "/frames.csv";
  poses_.open(poses_path, std::ios::trunc);
  frames_.open(frames_path, std::ios::trunc);
  if (!poses_ || !frames_) throw InputError(dir + ": cannot write poses.txt and frames.csv");
  poses_ << FormatTum({}) << std::flush;
  frames_ << "frame,time,status,projection_error_deg,moving_edges,time_ms,source,passes,state,"
          << kIntegrityCsvColumns;
  if (with_ground_truth_) frames_ << ",translation_error_m,rotation_error_deg";
  frames_ << ",note\n" << std::flush;
}

void ReplayLog::Add(const ReplayFrameRecord& record, const FrameReport& report) {
  const PoseUncertainty& u = report.uncertainty;
  if (report.cam_from_world && (all_poses_ || u.status == IntegrityStatus::kTracking)) {
    StampedPose pose;
    pose.t = record.t;
    pose.world_from_cam = report.cam_from_world->inverse();
    const std::string text = FormatTum({pose});
    poses_ << text.substr(text.find('\n') + 1) << std::flush;
  }
  // The note: why there is no pose, else why the pose is not tracking.
  std::string note = report.note.empty() ? u.reason : report.note;
  std::replace(note.begin(), note.end(), ',', ';');
  std::replace(note.begin(), note.end(), '\n', ' ');
  frames_ << record.frame << "," << Fixed(record.t, 6) << "," << ToString(u.status) << ","
          << (report.health_measured ? Fixed(record.projection_error_deg, 3) : "") << ","
          << (report.health_measured ? std::to_string(record.edges_good) : "") << ","
          << Fixed(record.step_ms, 3) << "," << report.source << "," << report.health.passes << ","
          << ToString(record.status) << "," << IntegrityCsvFields(u);
  if (with_ground_truth_) {
    frames_ << "," << (record.translation_error_m ? Fixed(*record.translation_error_m, 5) : "")
            << "," << (record.rotation_error_deg ? Fixed(*record.rotation_error_deg, 4) : "");
  }
  frames_ << "," << note << "\n" << std::flush;
  covariance_.Add(record.frame, record.t, u);
}

OverlayWriter::OverlayWriter(const std::string& dir, bool png_frames, double fps, cv::Size size)
    : png_(png_frames) {
  if (png_) {
    path_ = dir + "/overlay";
    codec_ = "png";
    std::error_code ec;
    std::filesystem::create_directories(path_, ec);
    if (ec) throw InputError(path_ + ": cannot create the overlay folder");
    return;
  }
  struct Choice {
    const char* file;
    const char* fourcc;
  };
  for (const Choice& c : {Choice{"overlay.mp4", "avc1"}, Choice{"overlay.mp4", "mp4v"},
                          Choice{"overlay.avi", "MJPG"}}) {
    path_ = dir + "/" + c.file;
    if (video_.open(path_,
                    cv::VideoWriter::fourcc(c.fourcc[0], c.fourcc[1], c.fourcc[2], c.fourcc[3]),
                    fps, size, true)) {
      codec_ = c.fourcc;
      return;
    }
  }
  throw InputError(dir + ": this OpenCV cannot write an overlay video (use --overlay-png)");
}

void OverlayWriter::Add(const cv::Mat& bgr, long frame) {
  if (png_) {
    char name[32];
    std::snprintf(name, sizeof(name), "/frame_%05ld.png", frame);
    cv::imwrite(path_ + name, bgr);
  } else if (video_.isOpened()) {
    video_.write(bgr);
  }
}

void OverlayWriter::Close() {
  if (video_.isOpened()) video_.release();
}

OverlayWriter::~OverlayWriter() {
  Close();
}

cv::Mat DrawOverlay(const vpImage<unsigned char>& undistorted,
                    const std::vector<Segment2>& model_edges, const FrameReport& report, long frame,
                    double t) {
  const cv::Mat grey(static_cast<int>(undistorted.getHeight()),
                     static_cast<int>(undistorted.getWidth()), CV_8UC1,
                     const_cast<unsigned char*>(undistorted.bitmap));
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  const cv::Scalar colour = StatusColour(report);
  const PoseUncertainty& u = report.uncertainty;
  for (const Segment2& s : model_edges) {
    cv::line(bgr, cv::Point2d(s.a.x(), s.a.y()), cv::Point2d(s.b.x(), s.b.y()), colour, 1,
             cv::LINE_AA);
  }
  Text(&bgr,
       "frame " + std::to_string(frame) + "  t " + Fixed(t, 2) + " s  " + ToString(u.status) +
           "  [" + ToString(report.status) + (report.source.empty() ? "" : ", " + report.source) +
           "]",
       {8, 18}, colour);
  if (report.cam_from_world) {
    const RobotPose p = RobotPoseFromCamFromWorld(*report.cam_from_world);
    Text(&bgr,
         "x " + Fixed(p.x, 3) + "  y " + Fixed(p.y, 3) + "  z " + Fixed(p.height, 3) +
             " m  heading " + Fixed(RadToDeg(WrapAngle(p.heading)), 1) + "  tilt " +
             Fixed(RadToDeg(p.tilt), 1) + " deg",
         {8, 38}, colour);
    Text(&bgr,
         "projection error " + Fixed(report.health.projection_error_deg, 1) + " deg, " +
             std::to_string(report.health.edges_good) + "/" +
             std::to_string(report.health.edges_total) + " moving edges",
         {8, 58}, colour);
    if (u.has_covariance()) {
      Text(&bgr,
           "sigma x " + Fixed(u.sigma_x_m * 100.0, 1) + " y " + Fixed(u.sigma_y_m * 100.0, 1) +
               " cm  heading " + Fixed(RadToDeg(u.sigma_heading_rad), 2) + " deg  PL " +
               Fixed(u.protection_position_m * 100.0, 1) + " cm / " +
               Fixed(RadToDeg(u.protection_rotation_rad), 2) + " deg",
           {8, 78}, colour);
    }
    if (u.status != IntegrityStatus::kTracking) Text(&bgr, u.reason.substr(0, 90), {8, 98}, colour);
  } else {
    Text(&bgr, report.note.substr(0, 90), {8, 38}, colour);
  }
  return bgr;
}

std::optional<cv::Mat> DrawErrorPlot(const std::vector<ReplayFrameRecord>& records) {
  double max_t = 0.0, max_r = 0.0;
  bool any = false;
  for (const ReplayFrameRecord& r : records) {
    if (!r.translation_error_m) continue;
    any = true;
    max_t = std::max(max_t, *r.translation_error_m * 100.0);
    max_r = std::max(max_r, *r.rotation_error_deg);
  }
  if (!any || records.empty()) return std::nullopt;
  // Axis tops: the next "nice" value (1, 2, 5 x 10^k) above the largest error.
  auto nice = [](double v) {
    const double base = std::pow(10.0, std::floor(std::log10(std::max(v, 1e-6))));
    for (double m : {1.0, 2.0, 5.0, 10.0}) {
      if (m * base >= v) return m * base;
    }
    return 10.0 * base;
  };
  const double top_t = nice(max_t), top_r = nice(max_r);
  const int width = 900, panel = 220, left = 70, right = 20, gap = 50, top = 30;
  cv::Mat plot(top + 2 * panel + gap + 40, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const double first = static_cast<double>(records.front().frame);
  const double span = std::max(1.0, static_cast<double>(records.back().frame) - first);
  auto x_of = [&](long frame) { return left + (frame - first) / span * (width - left - right); };
  auto draw_panel = [&](int y0, double top_value, const char* label, bool translation) {
    cv::rectangle(plot, {left, y0}, {width - right, y0 + panel}, {0, 0, 0}, 1);
    for (int k = 0; k <= 4; ++k) {
      const int y = y0 + panel - k * panel / 4;
      cv::line(plot, {left, y}, {width - right, y}, {220, 220, 220}, 1);
      cv::putText(plot, Fixed(top_value * k / 4, top_value < 1 ? 2 : 1), {5, y + 4},
                  cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0}, 1, cv::LINE_AA);
    }
    cv::putText(plot, label, {left, y0 - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1,
                cv::LINE_AA);
    cv::Point previous(-1, -1);
    for (const ReplayFrameRecord& r : records) {
      const int x = static_cast<int>(x_of(r.frame));
      if (!r.translation_error_m) {
        // Frames without a pose: a red tick on the axis.
        cv::line(plot, {x, y0 + panel}, {x, y0 + panel - 8}, {0, 0, 255}, 1);
        previous = {-1, -1};
        continue;
      }
      const double value = translation ? *r.translation_error_m * 100.0 : *r.rotation_error_deg;
      const cv::Point p(x, static_cast<int>(y0 + panel - std::min(value / top_value, 1.0) * panel));
      if (previous.x >= 0) cv::line(plot, previous, p, {180, 80, 0}, 1, cv::LINE_AA);
      previous = p;
    }
  };
  draw_panel(top, top_t, "camera position error (cm)", true);
  draw_panel(top + panel + gap, top_r, "rotation error (deg)", false);
  const int axis_y = top + 2 * panel + gap + 18;
  cv::putText(plot, "frame " + std::to_string(records.front().frame), {left, axis_y},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(plot, "frame " + std::to_string(records.back().frame) + "   (red: no pose)",
              {width - right - 240, axis_y}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0}, 1,
              cv::LINE_AA);
  return plot;
}

nlohmann::ordered_json ReplaySummary(const std::vector<ReplayFrameRecord>& records,
                                     const ReplayRunInfo& info) {
  int counts[5] = {0, 0, 0, 0, 0};
  int with_pose = 0;
  std::vector<double> step, decode, translation, rotation;
  for (const ReplayFrameRecord& r : records) {
    ++counts[static_cast<int>(r.status)];
    with_pose += r.has_pose ? 1 : 0;
    step.push_back(r.step_ms);
    decode.push_back(r.decode_ms);
    if (r.translation_error_m) {
      translation.push_back(*r.translation_error_m);
      rotation.push_back(*r.rotation_error_deg);
    }
  }
  const double n = static_cast<double>(records.size());
  const double busy_s = std::max(1e-9, info.wall_s - info.overlay_s);
  nlohmann::ordered_json summary = {
      {"complete", info.complete},
      {"interrupted", !info.complete},
      {"interruption", info.interruption},
      {"input", info.input},
      {"model", info.model},
      {"camera", info.camera},
      {"settings", info.settings},
      {"frames", records.size()},
      {"tracked", with_pose},
      {"tracked_share", n > 0 ? with_pose / n : 0.0},
      {"status_counts",
       {{"initialising", counts[static_cast<int>(TrackStatus::kInitialising)]},
        {"tracking", counts[static_cast<int>(TrackStatus::kTracking)]},
        {"lost", counts[static_cast<int>(TrackStatus::kLost)]},
        {"relocalised", counts[static_cast<int>(TrackStatus::kRelocalised)]},
        {"coasting", counts[static_cast<int>(TrackStatus::kCoasting)]}}},
      {"losses", info.losses},
      {"recoveries", info.recoveries},
      {"timing_ms", {{"step", Percentiles(step)}, {"decode", Percentiles(decode)}}},
      {"throughput_fps", n / busy_s},
      {"wall_s", info.wall_s},
      {"overlay_s", info.overlay_s},
      {"overlay", {{"path", info.overlay_path}, {"codec", info.overlay_codec}}},
      {"integrity", info.integrity}};
  if (!translation.empty()) {
    double sum_squares = 0.0;
    for (double e : translation)
      sum_squares += e * e;
    summary["ground_truth"] = {{"frames_compared", translation.size()},
                               {"ate_rmse_m", std::sqrt(sum_squares / translation.size())},
                               {"translation_m", Statistics(translation)},
                               {"rotation_deg", Statistics(rotation)},
                               {"per_frame", "frames.csv"},
                               {"plot", info.error_plot}};
  }
  return summary;
}

}  // namespace linetrack::app

#include "calibration/mount_output.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr int kPanelWidth = 240;
constexpr int kCaptionHeight = 34;
constexpr int kColumns = 5;
constexpr int kHeaderHeight = 30;
constexpr double kLongestArrowPx = 24.0;  // panel pixels for the largest used residual

std::string Fixed(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// A magnification for the residuals: a round number that draws the largest one about
// kLongestArrowPx long at panel scale `scale`.
double Magnification(const MountCalibration& mount, double scale) {
  double largest = 0.0;
  for (const MountViewReport& v : mount.views) {
    if (v.status != ViewStatus::kUsed) continue;
    for (const Eigen::Vector2d& r : v.residuals)
      largest = std::max(largest, r.norm());
  }
  if (!(largest > 0.0)) return 1.0;
  const double wanted = kLongestArrowPx / (largest * scale);
  const double decade = std::pow(10.0, std::floor(std::log10(wanted)));
  for (double step : {5.0, 2.0, 1.0})
    if (step * decade <= wanted) return step * decade;
  return decade;
}

void DrawPanel(const MountViewReport& v, double scale, double magnification, cv::Mat panel) {
  const bool used = v.status == ViewStatus::kUsed;
  panel.setTo(used ? cv::Scalar(45, 45, 45) : cv::Scalar(90, 90, 90));
  const int image_height = panel.rows - kCaptionHeight;
  cv::rectangle(panel, cv::Rect(0, 0, panel.cols, image_height), cv::Scalar(150, 150, 150), 1);
  const cv::Scalar dot = used ? cv::Scalar(200, 200, 200) : cv::Scalar(150, 150, 150);
  for (size_t k = 0; k < v.detection.image_points.size(); ++k) {
    const Eigen::Vector2d p = scale * v.detection.image_points[k];
    const cv::Point from(static_cast<int>(std::lround(p.x())),
                         static_cast<int>(std::lround(p.y())));
    cv::circle(panel, from, 1, dot, cv::FILLED);
    if (!used || k >= v.residuals.size()) continue;
    const Eigen::Vector2d q = p + scale * magnification * v.residuals[k];
    cv::line(panel, from,
             cv::Point(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y()))),
             cv::Scalar(60, 200, 255), 1, cv::LINE_AA);
  }
  const std::string first = v.name + "  " + Fixed("%.1f", RadToDeg(v.angles.pan)) + "/" +
                            Fixed("%.1f", RadToDeg(v.angles.tilt)) + " deg";
  const std::string second =
      used ? "RMS " + Fixed("%.3f", v.error_px) + " px" : std::string(ToString(v.status));
  cv::putText(panel, first, cv::Point(4, image_height + 14), cv::FONT_HERSHEY_SIMPLEX, 0.38,
              cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  cv::putText(panel, second, cv::Point(4, image_height + 29), cv::FONT_HERSHEY_SIMPLEX, 0.38,
              used ? cv::Scalar(120, 230, 120) : cv::Scalar(80, 160, 255), 1, cv::LINE_AA);
}

}  // namespace

std::string MountResidualsPng(const MountCalibration& mount, int width, int height) {
  const double scale = static_cast<double>(kPanelWidth) / std::max(width, 1);
  const int panel_height = static_cast<int>(std::lround(height * scale)) + kCaptionHeight;
  const int count = static_cast<int>(mount.views.size());
  const int columns = std::clamp(count, 1, kColumns);
  const int rows = std::max(1, (count + columns - 1) / columns);
  cv::Mat canvas(kHeaderHeight + rows * panel_height, columns * kPanelWidth, CV_8UC3,
                 cv::Scalar(25, 25, 25));
  const double magnification = Magnification(mount, scale);
  for (int i = 0; i < count; ++i) {
    const cv::Rect cell((i % columns) * kPanelWidth, kHeaderHeight + (i / columns) * panel_height,
                        kPanelWidth, panel_height);
    DrawPanel(mount.views[static_cast<size_t>(i)], scale, magnification, canvas(cell));
  }
  const std::string header = std::to_string(mount.UsedViews()) + " of " + std::to_string(count) +
                             " views used, RMS " + Fixed("%.3f", mount.rms_px) +
                             " px; residuals drawn x" + Fixed("%g", magnification) +
                             " (rejected views grey)";
  cv::putText(canvas, header, cv::Point(6, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  std::vector<unsigned char> png;
  cv::imencode(".png", canvas, png);
  return std::string(png.begin(), png.end());
}

OutputFiles MakeMountOutputs(const MountCalibration& mount, const MountRunInfo& info, int width,
                             int height) {
  OutputFiles files;
  files["mount.json"] = MountJson(mount, info);
  files["eMc.yaml"] = VispPoseYaml(mount.tilt_from_camera);
  files["residuals.png"] = MountResidualsPng(mount, width, height);
  return files;
}

std::string AnglesCsv(const std::vector<std::string>& images,
                      const std::vector<HeadAngles>& angles) {
  std::string text = "image,pan_deg,tilt_deg\n";
  char row[512];
  for (size_t i = 0; i < images.size() && i < angles.size(); ++i) {
    std::snprintf(row, sizeof(row), "%s,%.9f,%.9f\n", images[i].c_str(), RadToDeg(angles[i].pan),
                  RadToDeg(angles[i].tilt));
    text += row;
  }
  return text;
}

}  // namespace linetrack

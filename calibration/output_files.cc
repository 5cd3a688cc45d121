#include "calibration/output_files.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "models/errors.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

std::string ReadWholeFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string EncodePng(const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  cv::imencode(".png", image, bytes);
  return std::string(bytes.begin(), bytes.end());
}

// A distinct colour per view (hue around the circle), BGR.
cv::Scalar ViewColour(size_t index, size_t count) {
  const double hue =
      180.0 * static_cast<double>(index) / static_cast<double>(std::max<size_t>(count, 1));
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue, 230, 220)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

cv::Point ToPixel(const Eigen::Vector2d& p) {
  // Drawing with 4 fractional bits keeps sub-pixel positions.
  return cv::Point(static_cast<int>(std::lround(p.x() * 16)),
                   static_cast<int>(std::lround(p.y() * 16)));
}

nlohmann::ordered_json ErrorJson(double error) {
  return error >= 0.0 ? nlohmann::ordered_json(error) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json IntrinsicsJson(const CameraIntrinsics& c) {
  nlohmann::ordered_json j = {{"px", c.px}, {"py", c.py}, {"u0", c.u0}, {"v0", c.v0}};
  if (c.has_distortion) {
    j["kud"] = c.kud;
    j["kdu"] = c.kdu;
  }
  return j;
}

std::string AdditionalInfo(const CalibrationResult& result, const CalibrationOptions& options) {
  std::ostringstream info;
  info << "<calibration_tool>linetrack calibrate</calibration_tool>"
       << "<nb_calibration_images>" << result.UsedViews() << "</nb_calibration_images>"
       << "<calibration_pattern_type>" << ToString(options.pattern.kind)
       << "</calibration_pattern_type>"
       << "<board_size>" << options.pattern.cols << "x" << options.pattern.rows << "</board_size>"
       << "<square_size>" << options.pattern.square << "</square_size>"
       << "<global_reprojection_error><without_distortion>" << result.visp.global_error_without
       << "</without_distortion><with_distortion>" << result.visp.global_error_with
       << "</with_distortion></global_reprojection_error>";
  return info.str();
}

}  // namespace

std::string VispCameraXml(const CalibrationResult& result, const CalibrationOptions& options,
                          const std::string& camera_name) {
  // WriteCameraXml writes to a path: go through a private temporary file.
  std::error_code ec;
  const fs::path tmp = fs::temp_directory_path(ec) /
                       ("linetrack-calibrate-" + std::to_string(::getpid()) + "-camera.xml");
  CameraIntrinsics plain = result.visp.without, distorted = result.visp.final_model;
  plain.name = distorted.name = camera_name;
  WriteCameraXml(tmp.string(), plain, distorted, AdditionalInfo(result, options));
  const std::string text = ReadWholeFile(tmp);
  fs::remove(tmp, ec);
  return text;
}

std::string OpenCvYaml(const CalibrationResult& result, const CalibrationOptions& options) {
  const OpenCvCalibration& m = result.opencv;
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "nframes" << result.UsedViews();
  fs << "image_width" << result.width << "image_height" << result.height;
  fs << "board_width" << options.pattern.cols << "board_height" << options.pattern.rows;
  fs << "square_size" << options.pattern.square;
  fs << "pattern" << ToString(options.pattern.kind);
  if (options.opencv.fix_aspect_ratio) fs << "aspectRatio" << 1.0;
  fs << "flags" << m.flags;
  fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << m.fx, 0.0, m.cx, 0.0, m.fy, m.cy, 0, 0, 1);
  fs << "distortion_coefficients"
     << cv::Mat(5, 1, CV_64F, const_cast<double*>(m.distortion.data()));
  fs << "avg_reprojection_error" << m.rms;
  fs << "per_view_reprojection_errors" << cv::Mat(m.view_error, true);
  fs << "std_deviations_intrinsics" << cv::Mat(9, 1, CV_64F, const_cast<double*>(m.std_dev.data()));
  return fs.releaseAndGetString();
}

std::string RosCameraInfoYaml(const CalibrationResult& result, const std::string& camera_name) {
  const OpenCvCalibration& m = result.opencv;
  auto matrix = [](YAML::Emitter& out, const char* key, int rows, int cols,
                   const std::vector<double>& data) {
    out << YAML::Key << key << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "rows" << YAML::Value << rows << YAML::Key << "cols" << YAML::Value << cols;
    out << YAML::Key << "data" << YAML::Value << YAML::Flow << data << YAML::EndMap;
  };
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "image_width" << YAML::Value << result.width;
  out << YAML::Key << "image_height" << YAML::Value << result.height;
  out << YAML::Key << "camera_name" << YAML::Value << camera_name;
  matrix(out, "camera_matrix", 3, 3, {m.fx, 0, m.cx, 0, m.fy, m.cy, 0, 0, 1});
  out << YAML::Key << "distortion_model" << YAML::Value << "plumb_bob";
  matrix(out, "distortion_coefficients", 1, 5,
         std::vector<double>(m.distortion.begin(), m.distortion.end()));
  matrix(out, "rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  // Monocular: P = [K | 0] (no new camera matrix is chosen for rectified images).
  matrix(out, "projection_matrix", 3, 4, {m.fx, 0, m.cx, 0, 0, m.fy, m.cy, 0, 0, 0, 1, 0});
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string ReportJson(const CalibrationResult& result, const CalibrationOptions& options) {
  using nlohmann::ordered_json;
  const PatternSpec& p = options.pattern;
  ordered_json pattern = {
      {"kind", ToString(p.kind)}, {"cols", p.cols}, {"rows", p.rows}, {"square_m", p.square}};
  if (p.kind == PatternKind::kCharuco) {
    pattern["marker_m"] = p.MarkerSide();
    pattern["dictionary"] = p.dictionary;
  }
  const DetectionOptions& d = options.detection;
  ordered_json detection = {{"chessboard_sb", d.chessboard_sb},
                            {"subpix_half_window", d.subpix_half_window},
                            {"subpix_iterations", d.subpix_iterations},
                            {"subpix_epsilon_px", d.subpix_epsilon},
                            {"max_edge_blur_px", d.max_edge_blur_px}};
  ordered_json views = ordered_json::array(), rejected = ordered_json::array();
  for (const ViewReport& v : result.views) {
    ordered_json view = {{"name", v.name},
                         {"status", ToString(v.status)},
                         {"points", v.detection.image_points.size()},
                         {"edge_blur_px", v.detection.edge_blur_px},
                         {"error_px",
                          {{"visp_without_distortion", ErrorJson(v.error_visp_without)},
                           {"visp_with_distortion_final", ErrorJson(v.error_visp)},
                           {"opencv", ErrorJson(v.error_opencv)}}}};
    if (v.status != ViewStatus::kUsed) {
      view["reason"] = v.reason;
      rejected.push_back({{"name", v.name}, {"status", ToString(v.status)}, {"reason", v.reason}});
    }
    views.push_back(view);
  }
  const VispCalibration& vi = result.visp;
  const OpenCvCalibration& cv = result.opencv;
  ordered_json visp_with = IntrinsicsJson(vi.with);
  visp_with["global_error_px"] = vi.global_error_with;
  ordered_json visp_final = IntrinsicsJson(vi.final_model);
  visp_final["refined"] = vi.refined;
  visp_final["rms_px"] = vi.rms_final;
  visp_final["std_dev"] = {{"px", vi.std_dev(0)},
                           {"py", vi.std_dev(1)},
                           {"u0", vi.std_dev(2)},
                           {"v0", vi.std_dev(3)},
                           {"kud", vi.std_dev(4)}};
  ordered_json visp_without = IntrinsicsJson(vi.without);
  visp_without["global_error_px"] = vi.global_error_without;
  const char* names[] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
  ordered_json std_dev;
  for (size_t k = 0; k < 9; ++k)
    std_dev[names[k]] = cv.std_dev[k];
  ordered_json opencv = {{"flags", cv.flags}, {"fx", cv.fx},
                         {"fy", cv.fy},       {"cx", cv.cx},
                         {"cy", cv.cy},       {"distortion_k1_k2_p1_p2_k3", cv.distortion},
                         {"rms_px", cv.rms},  {"std_dev", std_dev}};
  ordered_json report = {{"image_size", {result.width, result.height}},
                         {"pattern", pattern},
                         {"detection", detection},
                         {"outlier_rejection",
                          {{"enabled", options.reject_outliers},
                           {"factor", options.outlier_factor},
                           {"min_error_px", options.outlier_min_error_px},
                           {"rounds", result.rejection_rounds}}},
                         {"views_total", result.views.size()},
                         {"views_used", result.UsedViews()},
                         {"views_rejected", rejected},
                         {"views", views},
                         {"visp",
                          {{"without_distortion", visp_without},
                           {"with_distortion_visp", visp_with},
                           {"with_distortion", visp_final}}},
                         {"opencv", opencv}};
  return report.dump(2) + "\n";
}

std::string CoveragePng(const CalibrationResult& result) {
  cv::Mat canvas(result.height, result.width, CV_8UC3, cv::Scalar(40, 40, 40));
  cv::rectangle(canvas, cv::Rect(0, 0, result.width, result.height), cv::Scalar(200, 200, 200), 1);
  const size_t count = result.views.size();
  for (size_t i = 0; i < count; ++i) {
    const ViewReport& v = result.views[i];
    if (!v.detection.found) continue;
    const bool used = v.status == ViewStatus::kUsed;
    const cv::Scalar colour = used ? ViewColour(i, count) : cv::Scalar(110, 110, 110);
    std::vector<cv::Point> points, hull;
    for (const Eigen::Vector2d& p : v.detection.image_points)
      points.push_back(ToPixel(p));
    cv::convexHull(points, hull);
    cv::polylines(canvas, hull, true, colour, 1, cv::LINE_AA, 4);
    for (const cv::Point& p : points) {
      if (used) {
        cv::circle(canvas, p, 3 * 16, colour, cv::FILLED, cv::LINE_AA, 4);
      } else {
        cv::drawMarker(canvas, cv::Point(p.x / 16, p.y / 16), colour, cv::MARKER_TILTED_CROSS, 6);
      }
    }
  }
  cv::putText(canvas,
              std::to_string(result.UsedViews()) + " views used, " +
                  std::to_string(count - static_cast<size_t>(result.UsedViews())) +
                  " rejected (grey)",
              cv::Point(8, result.height - 10), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  return EncodePng(canvas);
}

std::string OverlayPng(const CalibrationResult& result, const CalibrationOptions& options,
                       size_t view, const cv::Mat& gray) {
  const ViewReport& v = result.views[view];
  cv::Mat canvas;
  cv::cvtColor(gray, canvas, cv::COLOR_GRAY2BGR);
  const cv::Scalar green(60, 200, 60), red(40, 40, 230), orange(0, 150, 255);
  const bool used = v.status == ViewStatus::kUsed;
  for (const Eigen::Vector2d& p : v.detection.image_points)
    cv::circle(canvas, ToPixel(p), 4 * 16, used ? green : orange, 1, cv::LINE_AA, 4);
  if (used && v.estimate_index >= 0) {
    const std::vector<Eigen::Vector3d> board = BoardPoints(options.pattern);
    const Eigen::Isometry3d& pose =
        result.visp.cam_from_board_final[static_cast<size_t>(v.estimate_index)];
    for (int id : v.detection.point_ids) {
      const Eigen::Vector2d uv =
          ProjectBoardPoint(result.visp.final_model, pose, board[static_cast<size_t>(id)]);
      cv::drawMarker(
          canvas,
          cv::Point(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y()))),
          red, cv::MARKER_CROSS, 7, 1);
    }
  }
  std::ostringstream caption;
  caption << v.name << ": " << ToString(v.status);
  if (v.error_visp >= 0.0) {
    caption.precision(3);
    caption << std::fixed << ", RMS " << v.error_visp << " px (ViSP), " << v.error_opencv
            << " px (OpenCV)";
  }
  cv::putText(canvas, caption.str(), cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(canvas, caption.str(), cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              used ? cv::Scalar(255, 255, 255) : orange, 1, cv::LINE_AA);
  if (!used && !v.reason.empty() && v.reason != ToString(v.status)) {
    cv::putText(canvas, v.reason, cv::Point(8, 40), cv::FONT_HERSHEY_SIMPLEX, 0.45, orange, 1,
                cv::LINE_AA);
  }
  return EncodePng(canvas);
}

OutputFiles MakeCalibrationOutputs(const CalibrationResult& result,
                                   const std::vector<CalibrationImage>& images,
                                   const CalibrationOptions& options,
                                   const std::string& camera_name) {
  OutputFiles files;
  files["camera.xml"] = VispCameraXml(result, options, camera_name);
  files["opencv.yml"] = OpenCvYaml(result, options);
  files["camera_info.yaml"] = RosCameraInfoYaml(result, camera_name);
  files["report.json"] = ReportJson(result, options);
  files["coverage.png"] = CoveragePng(result);
  for (size_t i = 0; i < images.size() && i < result.views.size(); ++i) {
    const std::string stem = fs::path(result.views[i].name).stem().string();
    files["overlays/" + stem + ".png"] = OverlayPng(result, options, i, images[i].gray);
  }
  return files;
}

void WriteOutputFolder(const OutputFiles& files, const std::string& dir) {
  std::error_code ec;
  fs::path target = fs::absolute(dir, ec).lexically_normal();
  if (target.filename().empty()) target = target.parent_path();  // "out/" -> "out"
  const fs::path staging = target.parent_path() /
                           (target.filename().string() + ".partial-" + std::to_string(::getpid()));
  auto fail = [&](const fs::path& path, const std::string& what) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    throw InputError(Located(path.string(), 0, what));
  };
  if (fs::exists(target, ec) && !fs::is_directory(target, ec)) {
    throw InputError(Located(dir, 0, "exists and is not a folder"));
  }
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec) fail(dir, "cannot create the output folder (" + ec.message() + ")");
  for (const auto& [name, content] : files) {
    const fs::path path = staging / name;
    fs::create_directories(path.parent_path(), ec);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << content;
    out.close();
    if (!out) fail(target / name, "cannot write the file");
  }
  if (!fs::exists(target, ec)) {
    fs::create_directories(target.parent_path(), ec);
    fs::rename(staging, target, ec);
    if (ec) fail(dir, "cannot create the output folder (" + ec.message() + ")");
    return;
  }
  // The folder exists: move each finished file in (each rename replaces one file atomically).
  for (const auto& [name, content] : files) {
    fs::create_directories((target / name).parent_path(), ec);
    fs::rename(staging / name, target / name, ec);
    if (ec) fail(target / name, "cannot write the file (" + ec.message() + ")");
  }
  fs::remove_all(staging, ec);
}

}  // namespace linetrack

#include "calibration/mount_file.h"

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpPoseVector.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "calibration/hand_eye.h"
#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kRigidTolerance = 1e-6;  // |R^T R - I|, |det R - 1|, last row
constexpr const char* kAnglesHeader = "image,pan_deg,tilt_deg";

std::string Trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

double AngleField(const std::string& field, const std::string& path, int line) {
  try {
    size_t used = 0;
    const double value = std::stod(field, &used);
    if (used == field.size() && std::isfinite(value)) return DegToRad(value);
  } catch (const std::exception&) {
  }
  throw InputError(Located(path, line, "not a finite angle in degrees: '" + field + "'"));
}

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

nlohmann::ordered_json MatrixJson(const Eigen::MatrixXd& m) {
  nlohmann::ordered_json values = nlohmann::ordered_json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      values.push_back(m(r, c));
  return values;
}

// `count` finite numbers at `key` of `j`, or an InputError naming the field.
std::vector<double> Numbers(const nlohmann::json& j, const std::string& key, size_t count,
                            const std::string& path) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() != count) {
    throw InputError(Located(
        path, 0, "'" + key + "' must be an array of " + std::to_string(count) + " numbers"));
  }
  std::vector<double> values;
  for (const nlohmann::json& v : j[key]) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      throw InputError(Located(path, 0, "'" + key + "' holds a value that is not a finite number"));
    }
    values.push_back(v.get<double>());
  }
  return values;
}

double Number(const nlohmann::json& j, const std::string& key, const std::string& where,
              const std::string& path) {
  if (!j.contains(key) || !j[key].is_number() || !std::isfinite(j[key].get<double>())) {
    throw InputError(Located(path, 0, "'" + where + key + "' must be a finite number"));
  }
  return j[key].get<double>();
}

Eigen::Isometry3d RigidTransform(const std::vector<double>& v, const std::string& path) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      m(r, c) = v[static_cast<size_t>(4 * r + c)];
  const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > kRigidTolerance ||
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > kRigidTolerance ||
      std::abs(rotation.determinant() - 1.0) > kRigidTolerance) {
    throw InputError(Located(path, 0, "'tilt_from_camera' is not a rigid transform"));
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotation;
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

nlohmann::ordered_json ViewJson(const MountViewReport& v) {
  nlohmann::ordered_json j = {{"image", v.name},
                              {"pan_deg", RadToDeg(v.angles.pan)},
                              {"tilt_deg", RadToDeg(v.angles.tilt)}};
  if (v.status == ViewStatus::kUsed) {
    j["rms_px"] = v.error_px;
  } else {
    j["status"] = ToString(v.status);
    j["reason"] = v.reason;
  }
  return j;
}

nlohmann::ordered_json FloorJson(const MountRunInfo& info) {
  const FloorCalibration& f = *info.floor;
  return {{"image", info.floor_image},
          {"pan_deg", RadToDeg(info.floor_angles.pan)},
          {"tilt_deg", RadToDeg(info.floor_angles.tilt)},
          {"board_thickness_m", info.board_thickness},
          {"crossing_height_m", f.floor.crossing_height},
          {"base_roll_deg", RadToDeg(f.floor.base_roll)},
          {"base_pitch_deg", RadToDeg(f.floor.base_pitch)},
          {"camera_height_level_m", f.camera_height},
          {"rms_px", f.rms_px},
          {"covariance",
           {{"parameters", {"crossing_height_m", "base_roll_rad", "base_pitch_rad"}},
            {"matrix", MatrixJson(f.covariance)}}},
          {"sigma",
           {{"crossing_height_mm", 1e3 * std::sqrt(f.covariance(0, 0))},
            {"base_roll_deg", RadToDeg(std::sqrt(f.covariance(1, 1)))},
            {"base_pitch_deg", RadToDeg(std::sqrt(f.covariance(2, 2)))}}}};
}

}  // namespace

std::vector<AnglesRow> ReadAnglesCsv(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "no such angles file"));
  }
  std::ifstream in(path);
  std::string line;
  int line_no = 0;
  bool header = false;
  std::vector<AnglesRow> rows;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string text = Trimmed(line);
    if (text.empty() || text[0] == '#') continue;
    if (!header) {
      std::string compact;
      for (char c : text)
        if (c != ' ' && c != '\t') compact += c;
      if (compact != kAnglesHeader) {
        throw InputError(
            Located(path, line_no,
                    std::string("expected the header ") + kAnglesHeader + ", got '" + text + "'"));
      }
      header = true;
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream split(text);
    std::string field;
    while (std::getline(split, field, ','))
      fields.push_back(Trimmed(field));
    if (fields.size() != 3 || fields[0].empty()) {
      throw InputError(Located(path, line_no, "expected image,pan_deg,tilt_deg"));
    }
    AnglesRow row{fields[0],
                  {AngleField(fields[1], path, line_no), AngleField(fields[2], path, line_no)},
                  line_no};
    for (const AnglesRow& previous : rows) {
      if (FileName(previous.image) == FileName(row.image)) {
        throw InputError(Located(path, line_no, "image '" + row.image + "' is listed twice"));
      }
    }
    rows.push_back(row);
  }
  if (!header) throw InputError(Located(path, 0, std::string("no header ") + kAnglesHeader));
  return rows;
}

HeadAngles AnglesOfImage(const std::vector<AnglesRow>& rows, const std::string& image_path,
                         const std::string& csv_path) {
  const std::string name = FileName(image_path);
  for (const AnglesRow& row : rows)
    if (FileName(row.image) == name) return row.angles;
  throw InputError(Located(csv_path, 0, "no head angles for the image " + image_path));
}

MountFile ReadMountFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(Located(path, 0, "no such mount file"));
  }
  std::ifstream in(path);
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(Located(path, 0, std::string("not valid JSON: ") + e.what()));
  }
  if (!j.is_object()) throw InputError(Located(path, 0, "not a JSON object"));
  MountFile mount;
  mount.tilt_from_camera = RigidTransform(Numbers(j, "tilt_from_camera", 16, path), path);
  if (!j.contains("covariance") || !j["covariance"].is_object()) {
    throw InputError(Located(path, 0, "'covariance' must be an object with a 'matrix'"));
  }
  const std::vector<double> c = Numbers(j["covariance"], "matrix", 36, path);
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < 6; ++k)
      mount.covariance(r, k) = c[static_cast<size_t>(6 * r + k)];
  mount.rms_px = Number(j, "rms_px", "", path);
  if (j.contains("floor")) {
    const nlohmann::json& f = j["floor"];
    if (!f.is_object()) throw InputError(Located(path, 0, "'floor' must be an object"));
    FloorGeometry floor;
    floor.crossing_height = Number(f, "crossing_height_m", "floor.", path);
    floor.base_roll = DegToRad(Number(f, "base_roll_deg", "floor.", path));
    floor.base_pitch = DegToRad(Number(f, "base_pitch_deg", "floor.", path));
    if (!(std::abs(floor.crossing_height) < 100.0)) {
      throw InputError(Located(path, 0, "'floor.crossing_height_m' must be within 100 m"));
    }
    mount.floor = floor;
  }
  return mount;
}

std::string MountJson(const MountCalibration& mount, const MountRunInfo& info) {
  using nlohmann::ordered_json;
  ordered_json used = ordered_json::array(), rejected = ordered_json::array();
  for (const MountViewReport& v : mount.views)
    (v.status == ViewStatus::kUsed ? used : rejected).push_back(ViewJson(v));
  const Eigen::Matrix<double, 6, 1> sigma = mount.covariance.diagonal().cwiseSqrt();
  ordered_json j = {
      {"tool", "linetrack calibrate-mount"},
      {"conventions",
       "base_from_camera = Rz(pan) Ry(tilt) tilt_from_camera; tilt frame: x forward at zero tilt, "
       "y left, z up, origin where the pan and tilt axes cross; pan counter-clockwise from above, "
       "tilt positive down; camera axes ViSP's (x right, y down, z forward); metres"},
      {"tilt_from_camera", MatrixJson(mount.tilt_from_camera.matrix())},
      {"covariance",
       {{"parameters",
         {"shift_x_m", "shift_y_m", "shift_z_m", "rotation_x_rad", "rotation_y_rad",
          "rotation_z_rad"}},
        {"parameterisation",
         "tilt_from_camera = (t + shift, Exp(rotation) R): a shift of the camera centre and a "
         "rotation vector, both in the tilt frame; intrinsics taken as exact"},
        {"noise_px", mount.noise_sigma_px},
        {"view_shift_px", mount.view_shift_px},
        {"matrix", MatrixJson(mount.covariance)}}},
      {"sigma",
       {{"position_mm", {1e3 * sigma[0], 1e3 * sigma[1], 1e3 * sigma[2]}},
        {"rotation_deg", {RadToDeg(sigma[3]), RadToDeg(sigma[4]), RadToDeg(sigma[5])}}}},
      {"rms_px", mount.rms_px},
      {"camera", info.camera_path},
      {"pattern",
       {{"kind", ToString(info.pattern.kind)},
        {"cols", info.pattern.cols},
        {"rows", info.pattern.rows},
        {"square_m", info.pattern.square}}},
      {"hand_eye_start",
       {{"tilt_from_camera", MatrixJson(mount.hand_eye_start.matrix())},
        {"visp_status", mount.hand_eye_status}}},
      {"board_in_base", MatrixJson(mount.base_from_board.matrix())},
      {"rotation_axis_spread", mount.axis_spread},
      {"outlier_rejection_rounds", mount.rejection_rounds},
      {"views_used", used},
      {"views_rejected", rejected}};
  if (info.floor) j["floor"] = FloorJson(info);
  return j.dump(2) + "\n";
}

std::string VispPoseYaml(const Eigen::Isometry3d& tilt_from_camera) {
  const vpPoseVector pose(VispHomogeneous(tilt_from_camera));
  std::ostringstream out;
  out << "# eMc of linetrack calibrate-mount: e = the head's tilt frame, c = the camera;\n"
      << "# vpPoseVector tx ty tz (m) tux tuy tuz (rad)\n"
      << "rows: 6\ncols: 1\ndata:\n";
  char value[64];
  for (unsigned k = 0; k < 6; ++k) {
    std::snprintf(value, sizeof(value), "%.17g", pose[k]);
    out << "  - [" << value << "]\n";
  }
  return out.str();
}

}  // namespace linetrack

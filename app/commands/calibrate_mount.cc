// `linetrack calibrate-mount`: the camera's mount on the pan-tilt head, from views of a board that
// stands still while the head turns (image files with their head angles, or live: the command
// drives the head through a grid of angles), and the head's height above the floor and its base's
// tilt from one view of the board lying on the floor. Method: calibration/mount_calibration.h,
// calibration/floor_calibration.h; docs/calibration.md.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "app/commands.h"
#include "app/image_arguments.h"
#include "app/mount_views.h"
#include "calibration/hand_eye.h"
#include "calibration/mount_output.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"

namespace linetrack::app {
namespace {

constexpr double kSameAngleRad = 1e-6;

struct CalibrateMountCommandOptions {
  std::vector<std::string> images;
  std::string angles_path, camera_path, out_dir;
  std::string source, head;  // live
  std::string pattern = "chessboard";
  MountCalibrationOptions mount;
  bool keep_all = false;
  std::string floor_board, floor_angles;
  double board_thickness = 0.0;
  int views = 20;
  double pan_range_deg = 20.0, tilt_range_deg = 12.0;
  std::string centre = "0,0";
  std::string head_model = "ptu46";
  double height = 1.3, board_distance = 1.0;  // the simulator
  std::string model_path;                     // the simulator's scene
};

// The views and their angles, the floor view when asked.
struct MountInputs {
  std::vector<std::string> names;
  std::vector<cv::Mat> images;
  std::vector<HeadAngles> angles;
  bool live = false;
  std::optional<cv::Mat> floor;
  std::string floor_name;
  HeadAngles floor_angles;
  DistortionModel distortion = DistortionModel::kKud;  // of the images (MountViews)
};

HeadAngles ParseAngles(const std::string& text, const std::string& flag) {
  const std::vector<double> v = ParseNumberList(text, 2, flag, "PAN_DEG,TILT_DEG");
  return {DegToRad(v[0]), DegToRad(v[1])};
}

// Bad input: every view at the same angles, or turns about one axis only.
void CheckAngleSpread(const std::vector<HeadAngles>& angles, const std::string& where,
                      double min_spread) {
  bool moved = false;
  std::vector<Eigen::Matrix3d> rotations;
  for (const HeadAngles& a : angles) {
    moved = moved || std::abs(a.pan - angles.front().pan) > kSameAngleRad ||
            std::abs(a.tilt - angles.front().tilt) > kSameAngleRad;
    rotations.push_back(BaseFromTiltRotation(a.pan, a.tilt));
  }
  if (angles.size() < 2 || !moved) {
    throw InputError(where + ": every image was taken at one head angle: the head must turn");
  }
  const double spread = RotationAxisSpread(rotations);
  if (spread < min_spread) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  ": the head turned about one axis only (rotation axes' spread %.3f < %.3f): "
                  "the mount is not observable; turn it in both pan and tilt",
                  spread, min_spread);
    throw InputError(where + text);
  }
}

void CheckOptions(CalibrateMountCommandOptions* opt) {
  const std::optional<PatternKind> kind = ParsePatternKind(opt->pattern);
  if (!kind) throw InputError("--pattern: expected chessboard, circles or charuco");
  opt->mount.pattern.kind = *kind;
  opt->mount.reject_outliers = !opt->keep_all;
  std::string why;
  if (!opt->mount.Check(&why)) throw InputError(why);
  const bool files = !opt->images.empty() || !opt->angles_path.empty();
  const bool live = !opt->source.empty() || !opt->head.empty();
  if (files == live) throw InputError("give either --images and --angles, or --source and --head");
  if (files && (opt->images.empty() || opt->angles_path.empty())) {
    throw InputError("--images and --angles go together");
  }
  if (live && (opt->source.empty() || opt->head.empty())) {
    throw InputError("--source and --head go together");
  }
  if (live && !opt->floor_board.empty() && opt->floor_angles.empty()) {
    throw InputError("--floor-board: give its --floor-angles when the head is driven live");
  }
  CheckRange(opt->board_thickness, 0.0, 0.2, "--board-thickness");
  if (opt->views < 4 || opt->views > 400) throw InputError("--views: must be in [4, 400]");
  CheckRange(opt->pan_range_deg, 1.0, 170.0, "--pan-range");
  CheckRange(opt->tilt_range_deg, 1.0, 80.0, "--tilt-range");
  CheckRange(opt->height, 0.05, 100.0, "--height");
  CheckRange(opt->board_distance, 0.1, 20.0, "--board-distance");
  HeadModel model;
  if (!ParseHeadModel(opt->head_model, &model)) {
    throw InputError("--head-model: expected ptu46 or biclops, got '" + opt->head_model + "'");
  }
}

MountInputs LoadInputs(const CalibrateMountCommandOptions& opt, const CameraIntrinsics& camera) {
  MountInputs in;
  std::vector<AnglesRow> rows;
  if (!opt.angles_path.empty()) rows = ReadAnglesCsv(opt.angles_path);
  if (!opt.images.empty()) {
    std::vector<std::string> paths;
    for (const std::string& path : ExpandImageArguments(opt.images)) {
      const bool floor =
          !opt.floor_board.empty() && std::filesystem::path(path).filename() ==
                                          std::filesystem::path(opt.floor_board).filename();
      if (!floor) paths.push_back(path);
    }
    for (CalibrationImage& image : LoadCalibrationImages(paths)) {
      in.names.push_back(image.name);
      in.images.push_back(image.gray);
    }
    for (const std::string& path : paths)
      in.angles.push_back(AnglesOfImage(rows, path, opt.angles_path));
    CheckAngleSpread(in.angles, opt.angles_path, opt.mount.min_axis_spread);
  }
  if (!opt.floor_board.empty()) {
    in.floor = LoadCalibrationImages({opt.floor_board}).front().gray;
    in.floor_name = std::filesystem::path(opt.floor_board).filename().string();
    in.floor_angles = opt.floor_angles.empty()
                          ? AnglesOfImage(rows, opt.floor_board, opt.angles_path)
                          : ParseAngles(opt.floor_angles, "--floor-angles");
    if (in.floor->cols != camera.width || in.floor->rows != camera.height) {
      throw InputError(Located(opt.floor_board, 0, "the image size differs from the camera's"));
    }
  }
  for (size_t i = 0; i < in.images.size(); ++i) {
    if (in.images[i].cols != camera.width || in.images[i].rows != camera.height) {
      throw InputError(Located(in.names[i], 0,
                               "the image size differs from the camera's (" +
                                   std::to_string(camera.width) + "x" +
                                   std::to_string(camera.height) + ")"));
    }
  }
  return in;
}

void GrabLive(const CalibrateMountCommandOptions& opt, const CameraIntrinsics& camera,
              MountInputs* in) {
  MountViewsPlan plan;
  plan.source_spec = opt.source;
  plan.head_spec = opt.head;
  const HeadAngles centre = ParseAngles(opt.centre, "--centre");
  plan.grid_centre = Eigen::Vector2d(centre.pan, centre.tilt);
  plan.angles = SweepGrid(
      plan.grid_centre, Eigen::Vector2d(DegToRad(opt.pan_range_deg), DegToRad(opt.tilt_range_deg)),
      opt.views);
  ParseHeadModel(opt.head_model, &plan.head_model);
  plan.camera_height = opt.height;
  plan.board_distance = opt.board_distance;
  plan.model_path = opt.model_path;
  MountViews views = GrabMountViews(plan, opt.mount.pattern, camera);
  in->live = true;
  in->names = std::move(views.names);
  in->images = std::move(views.images);
  in->angles = std::move(views.angles);
  in->distortion = views.distortion;
}

void PrintResult(const MountCalibration& m, const std::optional<FloorCalibration>& floor) {
  std::printf(
      "view                  pan deg  tilt deg  status             points  pose px  "
      "mount px\n");
  for (const MountViewReport& v : m.views) {
    std::printf("%-20s %8.3f %9.3f  %-18s %6zu %8.3f %9.3f\n", v.name.c_str(),
                RadToDeg(v.angles.pan), RadToDeg(v.angles.tilt), ToString(v.status),
                v.detection.image_points.size(), v.pose_error_px, v.error_px);
  }
  for (const MountViewReport& v : m.views)
    if (v.status != ViewStatus::kUsed)
      std::printf("rejected %s: %s\n", v.name.c_str(), v.reason.c_str());
  const Eigen::Vector3d t = 1e3 * m.tilt_from_camera.translation();
  const Eigen::Matrix<double, 6, 1> sigma = m.covariance.diagonal().cwiseSqrt();
  std::printf("camera centre in the tilt frame: %.2f %.2f %.2f mm (sigma %.2f %.2f %.2f mm)\n",
              t.x(), t.y(), t.z(), 1e3 * sigma[0], 1e3 * sigma[1], 1e3 * sigma[2]);
  const Eigen::Vector3d axis = m.tilt_from_camera.linear().col(2);
  std::printf(
      "optical axis in the tilt frame: pan %.3f deg, tilt %.3f deg (rotation sigma %.3f "
      "%.3f %.3f deg)\n",
      RadToDeg(std::atan2(axis.y(), axis.x())), RadToDeg(std::asin(-axis.z())), RadToDeg(sigma[3]),
      RadToDeg(sigma[4]), RadToDeg(sigma[5]));
  std::printf("%d of %zu views used, RMS %.3f px, rotation axes' spread %.2f\n", m.UsedViews(),
              m.views.size(), m.rms_px, m.axis_spread);
  if (floor) {
    std::printf(
        "floor: crossing %.4f m above it (sigma %.1f mm), base roll %.3f deg, pitch %.3f "
        "deg; camera %.4f m above it with the head level\n",
        floor->floor.crossing_height, 1e3 * std::sqrt(floor->covariance(0, 0)),
        RadToDeg(floor->floor.base_roll), RadToDeg(floor->floor.base_pitch), floor->camera_height);
  }
}

// The floor from its view; throws InputError when the board is not seen.
FloorCalibration Floor(const MountInputs& in, const MountCalibration& mount,
                       const CameraIntrinsics& camera, const CalibrateMountCommandOptions& opt) {
  const PatternDetection d = DetectPattern(*in.floor, opt.mount.pattern, opt.mount.detection);
  if (!d.found) {
    throw InputError(Located(opt.floor_board, 0, "the pattern was not found on the floor board"));
  }
  const BoardView view = ViewOfDetection(in.floor_name, d, BoardPoints(opt.mount.pattern));
  return CalibrateFloor(camera, view, in.floor_angles, mount.tilt_from_camera, mount.covariance,
                        opt.board_thickness);
}

int RunCalibrateMount(CalibrateMountCommandOptions opt) {
  CheckOptions(&opt);
  const CameraIntrinsics camera = LoadCamera(opt.camera_path);
  if (camera.width <= 0)
    throw InputError(opt.camera_path + ": the camera file gives no image size");
  MountInputs in = LoadInputs(opt, camera);
  if (!opt.source.empty()) GrabLive(opt, camera, &in);
  std::vector<PatternDetection> detections;
  for (const cv::Mat& image : in.images)
    detections.push_back(DetectPattern(image, opt.mount.pattern, opt.mount.detection));
  opt.mount.distortion = in.distortion;
  const MountCalibration mount =
      CalibrateMountFromDetections(in.names, in.angles, detections, camera, opt.mount);
  if (mount.status == MountStatus::kPatternNeverFound ||
      mount.status == MountStatus::kTooFewViews) {
    throw InputError(mount.message);
  }
  if (!mount.ok()) {
    std::cerr << "linetrack: mount calibration failed: " << mount.message << std::endl;
    return kExitJobFailed;
  }
  MountRunInfo info;
  info.camera_path = opt.camera_path;
  info.pattern = opt.mount.pattern;
  if (in.floor) {
    const FloorCalibration floor = Floor(in, mount, camera, opt);
    if (!floor.ok) {
      std::cerr << "linetrack: floor calibration failed: " << floor.failure << std::endl;
      return kExitJobFailed;
    }
    info.floor = floor;
    info.floor_image = in.floor_name;
    info.floor_angles = in.floor_angles;
    info.board_thickness = opt.board_thickness;
  }
  OutputFiles files = MakeMountOutputs(mount, info, camera.width, camera.height);
  if (in.live) {
    files["angles.csv"] = AnglesCsv(in.names, in.angles);
    for (size_t i = 0; i < in.images.size(); ++i) {
      std::vector<unsigned char> png;
      cv::imencode(".png", in.images[i], png);
      files["views/" + in.names[i]] = std::string(png.begin(), png.end());
    }
  }
  WriteOutputFolder(files, opt.out_dir);
  PrintResult(mount, info.floor);
  std::cout << "wrote " << opt.out_dir << ": mount.json eMc.yaml residuals.png"
            << (in.live ? " angles.csv views/" : "") << std::endl;
  return kExitOk;
}

}  // namespace

void AddCalibrateMount(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<CalibrateMountCommandOptions>();
  CLI::App* cmd = cli.add_subcommand(
      "calibrate-mount",
      "The camera's mount on the pan-tilt head (tilt_from_camera) from views of a board standing "
      "still while the head turns, and the head's height above the floor from the board lying on "
      "it; writes mount.json (for live/replay --mount), eMc.yaml and residuals.png into --out");
  cmd->add_option("--images", opt->images, "Image files or glob patterns of the standing board");
  cmd->add_option("--angles", opt->angles_path, "ANGLES.csv: image,pan_deg,tilt_deg");
  cmd->add_option(
         "--camera", opt->camera_path,
         "Camera file: ViSP XML (linetrack calibrate), OpenCV or ROS YAML, with its image size")
      ->required();
  cmd->add_option("--pattern", opt->pattern, "chessboard, circles or charuco")
      ->capture_default_str();
  cmd->add_option("--cols", opt->mount.pattern.cols, "Inner corners (or dots) per row")
      ->capture_default_str();
  cmd->add_option("--rows", opt->mount.pattern.rows, "Inner corners (or dots) per column")
      ->capture_default_str();
  cmd->add_option("--square", opt->mount.pattern.square, "Square size or dot spacing (metres)")
      ->capture_default_str();
  cmd->add_option("--marker", opt->mount.pattern.marker, "ChArUco marker side (metres)");
  cmd->add_option("--dictionary", opt->mount.pattern.dictionary, "ChArUco ArUco dictionary")
      ->capture_default_str();
  cmd->add_option("--out", opt->out_dir, "Output folder (written only when all succeeded)")
      ->required();
  cmd->add_option("--floor-board", opt->floor_board,
                  "A view of the same board lying flat on the floor (its angles from --angles or "
                  "--floor-angles): the crossing's height and the base's tilt");
  cmd->add_option("--floor-angles", opt->floor_angles, "PAN_DEG,TILT_DEG of --floor-board");
  cmd->add_option("--board-thickness", opt->board_thickness,
                  "The floor board's surface above the floor (metres)")
      ->capture_default_str();
  cmd->add_flag("--keep-all", opt->keep_all, "Do not reject outlier views");
  cmd->add_option("--outlier-factor", opt->mount.outlier_factor,
                  "A view is an outlier when its RMS error exceeds this times the median")
      ->capture_default_str();
  cmd->add_option("--outlier-min-error", opt->mount.outlier_min_error_px,
                  "... and exceeds this many pixels")
      ->capture_default_str();
  cmd->add_option("--max-blur", opt->mount.detection.max_edge_blur_px,
                  "Views whose edge blur estimate (Gaussian sigma, px) exceeds this are rejected")
      ->capture_default_str();
  cmd->add_option("--source", opt->source,
                  "Live: aravis[:ID] | v4l2:/dev/videoN | sim[:ARGS] (with --head)");
  cmd->add_option("--head", opt->head, "Live: ptu:/dev/ttyUSB0 | sim; driven through a grid");
  cmd->add_option("--views", opt->views, "Live: views in the grid (at least)")
      ->capture_default_str();
  cmd->add_option("--pan-range", opt->pan_range_deg, "Live: the grid's pan, +- degrees")
      ->capture_default_str();
  cmd->add_option("--tilt-range", opt->tilt_range_deg, "Live: the grid's tilt, +- degrees")
      ->capture_default_str();
  cmd->add_option("--centre", opt->centre, "Live: the grid's centre PAN_DEG,TILT_DEG")
      ->capture_default_str();
  cmd->add_option("--head-model", opt->head_model, "sim: the head's nominal mount ptu46|biclops")
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "sim: the camera above the floor, head level (m)")
      ->capture_default_str();
  cmd->add_option("--board-distance", opt->board_distance,
                  "sim: the board's centre from the camera at the grid's centre (m)")
      ->capture_default_str();
  cmd->add_option("--model", opt->model_path, "sim: a .cao model around the board (default none)");
  cmd->callback([opt, action] { *action = [opt] { return RunCalibrateMount(*opt); }; });
}

}  // namespace linetrack::app

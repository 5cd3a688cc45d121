#include "calibration/mount_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calibration/board_pose.h"
#include "calibration/hand_eye.h"
#include "calibration/view_shift.h"
#include "models/pan_tilt.h"
#include "models/statistics.h"

namespace linetrack {
namespace {

std::string Format(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c);
  return buffer;
}

// One input image as the estimation sees it.
struct ViewData {
  BoardView view;
  BoardPose pose;  // its own pose (known intrinsics)
};

// Marks every view's fate from its detection and own pose; returns how many showed the board.
int ClassifyViews(const std::vector<PatternDetection>& detections, const CameraIntrinsics& camera,
                  const MountCalibrationOptions& options, std::vector<ViewData>* data,
                  MountCalibration* result) {
  const std::vector<Eigen::Vector3d> board = BoardPoints(options.pattern);
  int found = 0;
  for (size_t i = 0; i < detections.size(); ++i) {
    MountViewReport& report = result->views[i];
    report.detection = detections[i];
    if (!report.detection.found) {
      report.status = ViewStatus::kPatternNotFound;
      report.reason = "pattern not found";
      continue;
    }
    ++found;
    if (report.detection.edge_blur_px > options.detection.max_edge_blur_px) {
      report.status = ViewStatus::kBlurred;
      report.reason = Format("edge blur %.2f px above the limit %.2f px",
                             report.detection.edge_blur_px, options.detection.max_edge_blur_px);
      continue;
    }
    (*data)[i].view = ViewOfDetection(report.name, report.detection, board);
    (*data)[i].pose = EstimateBoardPose(camera, (*data)[i].view, options.solver);
    if (!(*data)[i].pose.ok) {
      report.status = ViewStatus::kOutlier;
      report.reason = "no board pose: " + (*data)[i].pose.failure;
      continue;
    }
    report.status = ViewStatus::kUsed;
    report.pose_error_px = (*data)[i].pose.rms_px;
  }
  return found;
}

// The board's pose in the base frame seen by the first view through `mount`.
Eigen::Isometry3d BoardInBase(const HeadAngles& angles, const Eigen::Isometry3d& mount,
                              const Eigen::Isometry3d& cam_from_board) {
  Eigen::Isometry3d base_from_tilt = Eigen::Isometry3d::Identity();
  base_from_tilt.linear() = BaseFromTiltRotation(angles.pan, angles.tilt);
  return base_from_tilt * mount * cam_from_board;
}

// Hand-eye start and joint refinement on the views `used`; false with result->status and
// message set on failure. Fills the per-view errors and residuals of the used views.
bool EstimateOnViews(const std::vector<size_t>& used, const std::vector<ViewData>& data,
                     const CameraIntrinsics& camera, const MountCalibrationOptions& options,
                     MountCalibration* result) {
  std::vector<BoardView> views;
  std::vector<HeadAngles> angles;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Isometry3d> cam_from_board;
  for (size_t i : used) {
    views.push_back(data[i].view);
    angles.push_back(result->views[i].angles);
    rotations.push_back(BaseFromTiltRotation(angles.back().pan, angles.back().tilt));
    cam_from_board.push_back(data[i].pose.cam_from_board);
  }
  result->axis_spread = RotationAxisSpread(rotations);
  if (result->axis_spread < options.min_axis_spread) {
    result->status = MountStatus::kUnobservable;
    result->message = Format(
        "the head turned about one axis only (rotation axes' spread %.3f < %.3f): the mount is "
        "not observable; turn the head in both pan and tilt",
        result->axis_spread, options.min_axis_spread);
    return false;
  }
  const HandEyeStart start = HandEyeMount(rotations, cam_from_board);
  if (!start.ok) {
    result->status = MountStatus::kEstimationFailed;
    result->message = start.failure;
    return false;
  }
  result->hand_eye_start = start.tilt_from_camera;
  result->hand_eye_status = start.visp_status;
  std::vector<Eigen::Isometry3d> poses = {
      start.tilt_from_camera, BoardInBase(angles[0], start.tilt_from_camera, cam_from_board[0])};
  const PoseResiduals residuals = MountResiduals(camera, views, angles, options.distortion);
  const PoseLeastSquaresResult solved = SolvePoseLeastSquares(residuals, options.solver, &poses);
  if (!solved.ok) {
    result->status = MountStatus::kEstimationFailed;
    result->message = "mount refinement: " + solved.failure;
    return false;
  }
  result->tilt_from_camera = poses[0];
  result->base_from_board = poses[1];
  result->rms_px = std::sqrt(solved.cost / (0.5 * solved.residuals));
  Eigen::VectorXd r;
  Eigen::MatrixXd jacobian;
  residuals(poses, &r, &jacobian);
  std::vector<int> points;
  for (const BoardView& v : views)
    points.push_back(static_cast<int>(v.image_points.size()));
  const ViewShiftCovariance shared =
      EstimateViewShiftCovariance(jacobian, r, points, options.view_shift_px);
  if (!shared.ok) {
    result->status = MountStatus::kEstimationFailed;
    result->message = "mount refinement: a direction of the poses is not observed";
    return false;
  }
  result->covariance = shared.covariance.topLeftCorner<6, 6>();
  result->noise_sigma_px = shared.sigma_px;
  result->view_shift_px = shared.tau_px;
  result->view_shift_data_px = shared.tau_data_px;
  Eigen::Index row = 0;
  for (size_t k = 0; k < used.size(); ++k) {
    MountViewReport& report = result->views[used[k]];
    report.residuals.clear();
    double sum = 0.0;
    for (size_t p = 0; p < views[k].image_points.size(); ++p, row += 2) {
      report.residuals.push_back(-r.segment<2>(row));  // detected minus predicted
      sum += r.segment<2>(row).squaredNorm();
    }
    report.error_px = std::sqrt(sum / static_cast<double>(views[k].image_points.size()));
  }
  return true;
}

}  // namespace

bool MountCalibrationOptions::Check(std::string* why) const {
  if (!pattern.Check(why) || !detection.Check(why) || !solver.Check(why)) return false;
  if (!CheckOutlierRule(outlier_factor, outlier_min_error_px, why)) return false;
  if (min_views < 3) {
    *why = "at least 3 views are needed to calibrate a mount";
    return false;
  }
  if (!(view_shift_px < 10.0)) {
    *why = "the view shift must be under 10 pixels (negative: estimated)";
    return false;
  }
  if (!(min_axis_spread >= 0.0 && min_axis_spread < 1.0)) {
    *why = "the minimum rotation axes' spread must be in [0, 1)";
    return false;
  }
  return true;
}

int MountCalibration::UsedViews() const {
  return static_cast<int>(std::count_if(views.begin(), views.end(), [](const MountViewReport& v) {
    return v.status == ViewStatus::kUsed;
  }));
}

PoseResiduals MountResiduals(const CameraIntrinsics& camera, const std::vector<BoardView>& views,
                             const std::vector<HeadAngles>& angles, DistortionModel model) {
  return [&camera, &views, &angles, model](const std::vector<Eigen::Isometry3d>& poses,
                                           Eigen::VectorXd* r, Eigen::MatrixXd* jacobian) {
    const Eigen::Isometry3d& mount = poses[0];
    const Eigen::Isometry3d& board = poses[1];
    Eigen::Index n = 0;
    for (const BoardView& v : views)
      n += static_cast<Eigen::Index>(v.board_points.size());
    r->resize(2 * n);
    if (jacobian != nullptr) jacobian->setZero(2 * n, 12);
    const Eigen::Matrix3d camera_from_tilt = mount.linear().transpose();
    Eigen::Matrix<double, 2, 3> d_pixel;
    Eigen::Index row = 0;
    for (size_t v = 0; v < views.size(); ++v) {
      const Eigen::Matrix3d tilt_from_base =
          BaseFromTiltRotation(angles[v].pan, angles[v].tilt).transpose();
      for (size_t k = 0; k < views[v].board_points.size(); ++k, row += 2) {
        const Eigen::Vector3d rotated = board.linear() * views[v].board_points[k];
        // Y: the point in the tilt frame; p = R_m^T (Y - t_m) in the camera.
        const Eigen::Vector3d from_camera =
            tilt_from_base * (rotated + board.translation()) - mount.translation();
        const Eigen::Vector3d p = camera_from_tilt * from_camera;
        if (!(p.z() > 0.0)) return false;
        r->segment<2>(row) = ProjectPoint(camera, p, jacobian ? &d_pixel : nullptr, model) -
                             views[v].image_points[k];
        if (jacobian == nullptr) continue;
        // Mount (t_m + s, Exp(w) R_m): dp/ds = -R_m^T, dp/dw = R_m^T [Y - t_m]x.
        // Board (t_b + s, Exp(w) R_b): dp/ds = R_m^T R_h^T, dp/dw = -R_m^T R_h^T [R_b X]x.
        const Eigen::Matrix3d to_camera = camera_from_tilt * tilt_from_base;
        jacobian->block<2, 3>(row, 0) = -d_pixel * camera_from_tilt;
        jacobian->block<2, 3>(row, 3) = d_pixel * camera_from_tilt * SkewMatrix(from_camera);
        jacobian->block<2, 3>(row, 6) = d_pixel * to_camera;
        jacobian->block<2, 3>(row, 9) = -d_pixel * to_camera * SkewMatrix(rotated);
      }
    }
    return true;
  };
}

MountCalibration CalibrateMountFromDetections(const std::vector<std::string>& names,
                                              const std::vector<HeadAngles>& angles,
                                              const std::vector<PatternDetection>& detections,
                                              const CameraIntrinsics& camera,
                                              const MountCalibrationOptions& options) {
  MountCalibration result;
  result.views.resize(detections.size());
  for (size_t i = 0; i < detections.size(); ++i) {
    result.views[i].name = i < names.size() ? names[i] : "view " + std::to_string(i);
    result.views[i].angles = i < angles.size() ? angles[i] : HeadAngles{};
  }
  std::vector<ViewData> data(detections.size());
  if (ClassifyViews(detections, camera, options, &data, &result) == 0) {
    result.status = MountStatus::kPatternNeverFound;
    result.message = PatternNeverFoundMessage(options.pattern, detections.size());
    return result;
  }
  while (true) {
    std::vector<size_t> used;
    for (size_t i = 0; i < result.views.size(); ++i)
      if (result.views[i].status == ViewStatus::kUsed) used.push_back(i);
    if (static_cast<int>(used.size()) < options.min_views) {
      result.status = MountStatus::kTooFewViews;
      result.message = "only " + std::to_string(used.size()) + " usable views of " +
                       std::to_string(detections.size()) + " images (at least " +
                       std::to_string(options.min_views) + " needed)";
      return result;
    }
    if (!EstimateOnViews(used, data, camera, options, &result)) return result;
    std::vector<double> errors;
    for (size_t i : used)
      errors.push_back(result.views[i].error_px);
    const int outlier = options.reject_outliers ? FindOutlierView(errors, options.outlier_factor,
                                                                  options.outlier_min_error_px)
                                                : -1;
    if (outlier < 0 || static_cast<int>(used.size()) <= options.min_views) break;
    MountViewReport& v = result.views[used[static_cast<size_t>(outlier)]];
    v.status = ViewStatus::kOutlier;
    v.reason = Format("RMS error %.3f px above %.1f x the median view error %.3f px", v.error_px,
                      options.outlier_factor, Median(errors));
    ++result.rejection_rounds;
  }
  result.status = MountStatus::kOk;
  return result;
}

}  // namespace linetrack

#include "app/mount_views.h"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "models/render/board_surfaces.h"
#include "tracking/capture/source_factory.h"
#include "tracking/head/head_factory.h"
#include "tracking/head/head_pointing.h"
#include "tracking/sim/sim_camera.h"
#include "tracking/sim/simulated_head.h"

namespace linetrack::app {
namespace {

constexpr double kBoardYawDeg = 15.0;    // the simulated board turned about the vertical
constexpr double kBoardPitchDeg = 10.0;  // and about its rows

MountViews Collect(PanTiltHead* head, FrameSource* source, const MountViewsPlan& plan,
                   const CameraIntrinsics& camera) {
  MountViews views;
  views.source = source->Describe();
  views.head = head->Describe();
  spdlog::info("calibrate-mount: {} views, source {}, head {}", plan.angles.size(), views.source,
               views.head);
  const SweepResult sweep = SweepHead(head, source, plan.angles, plan.sweep);
  head->Stop();
  if (!sweep.ok) throw std::runtime_error("calibrate-mount: " + sweep.failure);
  for (size_t i = 0; i < sweep.views.size(); ++i) {
    const vpImage<unsigned char>& image = sweep.views[i].frame.image;
    if (static_cast<int>(image.getWidth()) != camera.width ||
        static_cast<int>(image.getHeight()) != camera.height) {
      throw InputError("--source " + plan.source_spec + ": frames of " +
                       std::to_string(image.getWidth()) + "x" + std::to_string(image.getHeight()) +
                       ", the camera is " + std::to_string(camera.width) + "x" +
                       std::to_string(camera.height));
    }
    char name[32];
    std::snprintf(name, sizeof(name), "view_%02zu.png", i + 1);
    views.names.push_back(name);
    views.images.push_back(
        cv::Mat(camera.height, camera.width, CV_8U, const_cast<unsigned char*>(image.bitmap))
            .clone());
    views.angles.push_back({sweep.views[i].head.pan, sweep.views[i].head.tilt});
  }
  return views;
}

MountViews GrabSimulated(const MountViewsPlan& plan, const PatternSpec& pattern,
                         const CameraIntrinsics& camera, const std::string& arguments) {
  if (pattern.kind != PatternKind::kChessboard) {
    throw InputError("--source sim: the simulated board is a chessboard (--pattern chessboard)");
  }
  SimCameraOptions options;
  options.path = SimPath::kStill;
  options.camera_height = plan.camera_height;
  options.head_model = plan.head_model;
  ParseSimArguments(arguments, &options);
  // The board stands where the robot believes its nominal camera looks.
  const HeadGeometry nominal = GeometryOf(plan.head_model);
  ChessboardSurfaceOptions board;
  board.cols = pattern.cols;
  board.rows = pattern.rows;
  board.square = pattern.square;
  options.render_options.scene.extra_surfaces = ChessboardSurfaces(
      SimulatedBoardPose(pattern, nominal, CrossingHeightFor(nominal, plan.camera_height),
                         plan.grid_centre, plan.board_distance),
      board);
  const WireframeModel model = plan.model_path.empty() ? WireframeModel::FromCao(CaoModel{})
                                                       : WireframeModel::Load(plan.model_path);
  SimulatedCamera source(model, nullptr, camera, options);
  SimulatedHead head;
  source.AttachHead(&head);
  return Collect(&head, &source, plan, camera);
}

}  // namespace

Eigen::Isometry3d SimulatedBoardPose(const PatternSpec& pattern, const HeadGeometry& nominal,
                                     double crossing_height, const Eigen::Vector2d& angles,
                                     double distance) {
  const Eigen::Isometry3d world_from_camera =
      CamFromWorldOnHead(nominal, Pose3Dof{}, crossing_height, angles.x(), angles.y()).inverse();
  // Board axes: x along the camera's x (right), y along its y (down), z away from the camera.
  Eigen::Isometry3d world_from_board = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(DegToRad(kBoardYawDeg), Eigen::Vector3d::UnitY()).toRotationMatrix() *
      Eigen::AngleAxisd(DegToRad(kBoardPitchDeg), Eigen::Vector3d::UnitX()).toRotationMatrix();
  world_from_board.linear() = world_from_camera.linear() * turn;
  const Eigen::Vector3d centre = world_from_camera * Eigen::Vector3d(0.0, 0.0, distance);
  const Eigen::Vector3d half((pattern.cols - 1) * pattern.square / 2.0,
                             (pattern.rows - 1) * pattern.square / 2.0, 0.0);
  world_from_board.translation() = centre - world_from_board.linear() * half;
  return world_from_board;
}

MountViews GrabMountViews(const MountViewsPlan& plan, const PatternSpec& pattern,
                          const CameraIntrinsics& camera) {
  const SourceSpec source = ParseSourceSpec(plan.source_spec);
  const HeadSpec head = ParseHeadSpec(plan.head_spec);
  if ((source.kind == SourceKind::kSim) != (head.kind == HeadKind::kSim)) {
    throw InputError("--source " + plan.source_spec + " --head " + plan.head_spec +
                     ": the simulated camera and the simulated head go together");
  }
  if (source.kind == SourceKind::kSim) {
    MountViews views = GrabSimulated(plan, pattern, camera, source.argument);
    views.distortion = DistortionModel::kInverseOfKdu;
    return views;
  }
  FrameSourceOptions sources;
  sources.aravis.width = camera.width;
  sources.aravis.height = camera.height;
  sources.aravis.latest_only = true;
  const std::unique_ptr<FrameSource> frames = OpenFrameSource(plan.source_spec, sources);
  const std::unique_ptr<PanTiltHead> unit = OpenHead(plan.head_spec, HeadOptions{});
  return Collect(unit.get(), frames.get(), plan, camera);
}

}  // namespace linetrack::app

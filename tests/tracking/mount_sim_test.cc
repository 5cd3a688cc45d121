// The simulator's side of the mount calibration: a bracket that is off moves the simulated
// camera by exactly that much; the live loop's priors follow the geometry it believes, not the
// simulator's truth; the head sweep stops at each angle of its grid, still, and keeps a frame
// there; and the rendered chessboard is found where the geometry puts its corners.
#include <gtest/gtest.h>

#include <cmath>

#include "calibration/detection.h"
#include "calibration/visp_calibration.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/pan_tilt.h"
#include "models/render/board_surfaces.h"
#include "tracking/head/head_pointing.h"
#include "tracking/head/head_sweep.h"
#include "tracking/sim/sim_camera.h"
#include "tracking/sim/sim_rig.h"

namespace linetrack {
namespace {

constexpr double kPoseTol = 1e-12;
constexpr double kAngleTol = 1e-9;  // radians: the simulated head stops on its target
// Detected corners against the projected truth. The renderer's 2 x 2 supersampling, blur and
// noise scatter them by about 0.2 px; their mean offset (a bias of the renderer's geometry) is
// held much tighter.
constexpr double kCornerBiasTolPx = 0.05;  // |mean offset|
constexpr double kCornerTolPx = 0.25;      // mean distance
constexpr double kCornerMaxTolPx = 0.5;    // worst corner

const std::string kSource = LINETRACK_SOURCE_DIR;

const WireframeModel& Empty() {
  static const WireframeModel model = WireframeModel::FromCao(CaoModel{});
  return model;
}

CameraIntrinsics WideCamera() {
  return ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
}

Eigen::Matrix<double, 6, 1> Bracket() {
  Eigen::Matrix<double, 6, 1> b;
  b << 0.003, -0.004, 0.002, DegToRad(0.8), DegToRad(-1.2), DegToRad(0.5);
  return b;
}

TEST(SimulatedBracket, ParsedAndAppliedToTheNominalMount) {
  SimCameraOptions options;
  options.render = false;
  ParseSimArguments("bracket_mm=3:-4:2,bracket_deg=0.8:-1.2:0.5", &options);
  EXPECT_LT((options.bracket_error - Bracket()).norm(), 1e-15);
  for (const char* bad : {"bracket_mm=1:2", "bracket_deg=a:0:0", "bracket_mm=200:0:0"}) {
    SimCameraOptions o;
    EXPECT_THROW(ParseSimArguments(bad, &o), InputError) << bad;
  }
  SimulatedCamera camera(Empty(), nullptr, WideCamera(), options);
  SimulatedHead head;
  camera.AttachHead(&head);
  Frame frame;
  ASSERT_EQ(camera.Grab(&frame), FrameStatus::kOk);
  HeadGeometry truth = GeometryOf(HeadModel::kPtu46);
  truth.tilt_from_camera = MovedPose(truth.tilt_from_camera, Bracket());
  EXPECT_NEAR(camera.crossing_height(), CrossingHeightFor(truth, options.camera_height), kPoseTol);
  EXPECT_TRUE(camera.last_cam_from_world().isApprox(
      CamFromWorldOnHead(truth, options.still_base, camera.crossing_height(), 0.0, 0.0), kPoseTol));
}

// The loop's prior is the camera pose the believed geometry gives: the nominal one is off by the
// bracket, the calibrated one (here the truth) is the simulator's camera.
TEST(SimulatedBracket, TheLoopsPriorFollowsTheBelievedGeometry) {
  SimCameraOptions sim;
  sim.render = false;
  sim.still_base = {3.0, 1.5, DegToRad(20.0)};
  sim.bracket_error = Bracket();
  LiveLoopOptions loop;
  loop.target = Eigen::Vector3d(9.25, 2.75, 1.5);
  const WireframeModel hall = WireframeModel::Load(kSource + "/models/hall.cao");
  SimulatedLiveRig nominal(
      hall, nullptr, WideCamera(),
      SimulatedLiveRigOptions{sim, SimulatedHeadOptions{}, NominalBelief(sim, loop), {}, {}});
  HeadGeometry truth = GeometryOf(HeadModel::kPtu46);
  truth.tilt_from_camera = MovedPose(truth.tilt_from_camera, Bracket());
  loop.servo.geometry = truth;
  loop.crossing_height = CrossingHeightFor(truth, sim.camera_height);
  SimulatedLiveRig calibrated(hall, nullptr, WideCamera(),
                              SimulatedLiveRigOptions{sim, SimulatedHeadOptions{}, loop, {}, {}});
  const LiveIteration a = nominal.loop().Step(), b = calibrated.loop().Step();
  const RobotPose seen = RobotPoseFromCamFromWorld(calibrated.camera().last_cam_from_world());
  EXPECT_NEAR(b.camera_prior.tilt, seen.tilt, 1e-9);
  EXPECT_NEAR(b.camera_prior.height, seen.height, 1e-9);
  EXPECT_NEAR(b.camera_prior.x, seen.x, 1e-9);
  EXPECT_GT(std::abs(a.camera_prior.tilt - seen.tilt), DegToRad(0.5));  // the bracket's pitch
}

TEST(HeadSweep, GridSpansBothAxesInASerpentine) {
  const std::vector<Eigen::Vector2d> grid =
      SweepGrid(Eigen::Vector2d(0.1, -0.05), Eigen::Vector2d(0.3, 0.2), 20);
  ASSERT_EQ(grid.size(), 20u);  // 5 x 4
  EXPECT_NEAR(grid.front().x(), -0.2, 1e-12);
  EXPECT_NEAR(grid.front().y(), -0.25, 1e-12);
  EXPECT_NEAR(grid[4].x(), 0.4, 1e-12);
  EXPECT_NEAR(grid[5].x(), 0.4, 1e-12);  // the next row comes back
  EXPECT_NEAR(grid.back().y(), 0.15, 1e-12);
}

TEST(HeadSweep, StopsStillAtEveryAngleAndKeepsAFrameThere) {
  SimCameraOptions options;
  options.render = false;
  SimulatedCamera camera(Empty(), nullptr, WideCamera(), options);
  SimulatedHead head;
  camera.AttachHead(&head);
  const std::vector<Eigen::Vector2d> grid =
      SweepGrid(Eigen::Vector2d::Zero(), Eigen::Vector2d(0.3, 0.2), 6);
  const SweepResult sweep = SweepHead(&head, &camera, grid, HeadSweepOptions{});
  ASSERT_TRUE(sweep.ok) << sweep.failure;
  ASSERT_EQ(sweep.views.size(), grid.size());
  for (size_t i = 0; i < grid.size(); ++i) {
    const SweepView& v = sweep.views[i];
    EXPECT_FALSE(v.head.moving);
    EXPECT_NEAR(v.head.pan, grid[i].x(), kAngleTol);
    EXPECT_NEAR(v.head.tilt, grid[i].y(), kAngleTol);
    if (i > 0) {
      EXPECT_GT(v.frame.index, sweep.views[i - 1].frame.index);
    }
  }
  // A target beyond the joint limits is refused, and the sweep says which view.
  const SweepResult refused =
      SweepHead(&head, &camera, {Eigen::Vector2d(0.0, 2.0)}, HeadSweepOptions{});
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.failure.find("view 1"), std::string::npos) << refused.failure;
}

// The renderer's chessboard, seen by the simulated camera, is detected where the camera's true
// pose projects its corners.
TEST(SimulatedBoard, DetectedWhereTheGeometryPutsItsCorners) {
  PatternSpec pattern;
  pattern.cols = 9;
  pattern.rows = 6;
  pattern.square = 0.04;
  SimCameraOptions options;
  // Facing the camera at pan and tilt zero, 0.9 m ahead, turned 15 deg about the vertical.
  const HeadGeometry nominal = GeometryOf(HeadModel::kPtu46);
  const double crossing = CrossingHeightFor(nominal, options.camera_height);
  const Eigen::Isometry3d world_from_camera =
      CamFromWorldOnHead(nominal, options.still_base, crossing, 0.0, 0.0).inverse();
  Eigen::Isometry3d world_from_board = Eigen::Isometry3d::Identity();
  world_from_board.linear() =
      world_from_camera.linear() *
      Eigen::AngleAxisd(DegToRad(15.0), Eigen::Vector3d::UnitY()).toRotationMatrix();
  world_from_board.translation() = world_from_camera * Eigen::Vector3d(0.0, 0.0, 0.9) -
                                   world_from_board.linear() * Eigen::Vector3d(0.16, 0.1, 0.0);
  ChessboardSurfaceOptions board;
  options.render_options.scene.extra_surfaces = ChessboardSurfaces(world_from_board, board);
  const CameraIntrinsics camera = WideCamera();
  SimulatedCamera source(Empty(), nullptr, camera, options);
  SimulatedHead head;
  source.AttachHead(&head);
  Frame frame;
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk);
  const cv::Mat image(camera.height, camera.width, CV_8U, frame.image.bitmap);
  const PatternDetection d = DetectPattern(image, pattern, DetectionOptions{});
  ASSERT_TRUE(d.found);
  const Eigen::Isometry3d cam_from_board = source.last_cam_from_world() * world_from_board;
  const std::vector<Eigen::Vector3d> points = BoardPoints(pattern);
  double sum = 0.0, worst = 0.0;
  Eigen::Vector2d mean_offset = Eigen::Vector2d::Zero();
  for (size_t k = 0; k < d.image_points.size(); ++k) {
    const Eigen::Vector2d offset =
        ProjectBoardPoint(camera, cam_from_board, points[static_cast<size_t>(d.point_ids[k])]) -
        d.image_points[k];
    const double e = offset.norm();
    mean_offset += offset / static_cast<double>(d.image_points.size());
    sum += e;
    worst = std::max(worst, e);
  }
  EXPECT_LT(mean_offset.norm(), kCornerBiasTolPx);
  EXPECT_LT(sum / d.image_points.size(), kCornerTolPx);
  EXPECT_LT(worst, kCornerMaxTolPx);
}

}  // namespace
}  // namespace linetrack

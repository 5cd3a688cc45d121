// The mount calibration on exact data: the projection's derivative and the residuals' analytic
// Jacobians against central differences, the joint refinement recovering a known mount from
// exact projections (and naming a view taken at wrong angles), the rotation axes' spread that
// detects a head turned about one axis, the floor's height and tilt from a board's pose, and the
// files: ANGLES.csv, mount.json read back, eMc.yaml read by ViSP.
#include <gtest/gtest.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpPoseVector.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "calibration/board_pose.h"
#include "calibration/floor_calibration.h"
#include "calibration/hand_eye.h"
#include "calibration/mount_file.h"
#include "calibration/visp_calibration.h"
#include "models/errors.h"
#include "tests/support/mount_scene.h"

namespace linetrack {
namespace {

using test_support::CamFromBoard;
using test_support::MakeMountScene;
using test_support::MountScene;

constexpr double kJacobianTol = 1e-5;   // pixels per unit of delta, central differences
constexpr double kExactPoseTol = 1e-8;  // metres, radians: exact projections
constexpr double kExactPx = 1e-9;

// Exact detections of the standing board in every view of `s` (all corners, in id order)
// under the distortion `model`.
std::vector<PatternDetection> ExactDetections(const MountScene& s,
                                              DistortionModel model = DistortionModel::kKud) {
  const std::vector<Eigen::Vector3d> board = BoardPoints(s.pattern);
  std::vector<PatternDetection> detections;
  for (const HeadAngles& a : s.angles) {
    PatternDetection d;
    d.found = true;
    const Eigen::Isometry3d pose = CamFromBoard(s.tilt_from_camera, s.base_from_board, a);
    for (size_t k = 0; k < board.size(); ++k) {
      d.image_points.push_back(ProjectPoint(s.camera, pose * board[k], nullptr, model));
      d.point_ids.push_back(static_cast<int>(k));
    }
    detections.push_back(d);
  }
  return detections;
}

std::vector<std::string> Names(size_t n) {
  std::vector<std::string> names;
  for (size_t i = 0; i < n; ++i)
    names.push_back("view_" + std::to_string(i) + ".png");
  return names;
}

MountCalibrationOptions Options(const MountScene& s) {
  MountCalibrationOptions options;
  options.pattern = s.pattern;
  return options;
}

TEST(MountMath, ProjectionDerivativeAndViSPsModel) {
  const MountScene s = MakeMountScene(1);
  const Eigen::Vector3d p(0.31, -0.22, 1.4);
  Eigen::Matrix<double, 2, 3> d;
  const Eigen::Vector2d uv = ProjectPoint(s.camera, p, &d);
  EXPECT_LT((uv - ProjectBoardPoint(s.camera, Eigen::Isometry3d::Identity(), p)).norm(), kExactPx);
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[k] = h;
    const Eigen::Vector2d numeric =
        (ProjectPoint(s.camera, p + step, nullptr) - ProjectPoint(s.camera, p - step, nullptr)) /
        (2 * h);
    EXPECT_LT((numeric - d.col(k)).norm(), kJacobianTol) << "column " << k;
  }
}

// The inverse of kdu: its pixel undistorts (CameraIntrinsics::Undistort) to the pinhole pixel,
// and its derivative matches central differences.
TEST(MountMath, ProjectionThroughTheInverseOfKdu) {
  MountScene s = MakeMountScene(1);
  s.camera.kdu = 0.085;
  const Eigen::Vector3d p(0.31, -0.22, 1.4);
  Eigen::Matrix<double, 2, 3> d;
  const Eigen::Vector2d uv = ProjectPoint(s.camera, p, &d, DistortionModel::kInverseOfKdu);
  EXPECT_LT((s.camera.Undistort(uv) - s.camera.Project(p)).norm(), kExactPx);
  EXPECT_GT((uv - s.camera.Project(p)).norm(), 0.5);  // the distortion is not negligible here
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step[k] = h;
    const Eigen::Vector2d numeric =
        (ProjectPoint(s.camera, p + step, nullptr, DistortionModel::kInverseOfKdu) -
         ProjectPoint(s.camera, p - step, nullptr, DistortionModel::kInverseOfKdu)) /
        (2 * h);
    EXPECT_LT((numeric - d.col(k)).norm(), kJacobianTol) << "column " << k;
  }
}

TEST(MountMath, AnalyticJacobiansMatchCentralDifferences) {
  const MountScene s = MakeMountScene(2);
  const std::vector<PatternDetection> detections = ExactDetections(s);
  std::vector<BoardView> views;
  for (const PatternDetection& d : detections)
    views.push_back(ViewOfDetection("v", d, BoardPoints(s.pattern)));
  // Poses away from the solution, so that the residuals are not zero.
  const Eigen::Matrix<double, 6, 1> off =
      (Eigen::Matrix<double, 6, 1>() << 0.01, -0.02, 0.005, 0.02, -0.01, 0.03).finished();
  const std::vector<Eigen::Isometry3d> mount_poses = {MovedPose(s.tilt_from_camera, off),
                                                      MovedPose(s.base_from_board, -off)};
  const PoseResiduals mount = MountResiduals(s.camera, views, s.angles);
  Eigen::VectorXd r;
  Eigen::MatrixXd analytic;
  ASSERT_TRUE(mount(mount_poses, &r, &analytic));
  const Eigen::MatrixXd numeric = NumericPoseJacobian(mount, mount_poses, 1e-6);
  ASSERT_EQ(numeric.rows(), analytic.rows());
  EXPECT_LT((numeric - analytic).cwiseAbs().maxCoeff(), kJacobianTol);

  const PoseResiduals board = BoardViewResiduals(s.camera, views[3]);
  const std::vector<Eigen::Isometry3d> board_pose = {
      MovedPose(CamFromBoard(s.tilt_from_camera, s.base_from_board, s.angles[3]), off)};
  ASSERT_TRUE(board(board_pose, &r, &analytic));
  EXPECT_LT((NumericPoseJacobian(board, board_pose, 1e-6) - analytic).cwiseAbs().maxCoeff(),
            kJacobianTol);
}

TEST(MountMath, BoardPoseFromExactPoints) {
  const MountScene s = MakeMountScene(3);
  const PatternDetection d = ExactDetections(s)[7];
  const BoardPose pose =
      EstimateBoardPose(s.camera, ViewOfDetection("v", d, BoardPoints(s.pattern)));
  ASSERT_TRUE(pose.ok) << pose.failure;
  const Eigen::Isometry3d truth = CamFromBoard(s.tilt_from_camera, s.base_from_board, s.angles[7]);
  EXPECT_LT(PoseDelta(pose.cam_from_board, truth).norm(), kExactPoseTol);
  EXPECT_LT(pose.rms_px, kExactPx);
}

TEST(MountCalibration, RecoversTheMountFromExactProjections) {
  const MountScene s = MakeMountScene(4);
  const MountCalibration m = CalibrateMountFromDetections(Names(s.angles.size()), s.angles,
                                                          ExactDetections(s), s.camera, Options(s));
  ASSERT_TRUE(m.ok()) << m.message;
  EXPECT_EQ(m.UsedViews(), static_cast<int>(s.angles.size()));
  EXPECT_LT(PoseDelta(m.tilt_from_camera, s.tilt_from_camera).norm(), kExactPoseTol);
  EXPECT_LT(PoseDelta(m.base_from_board, s.base_from_board).norm(), kExactPoseTol);
  EXPECT_LT(m.rms_px, 1e-6);
  // ViSP's closed form is already exact on exact poses.
  EXPECT_LT(PoseDelta(m.hand_eye_start, s.tilt_from_camera).norm(), 1e-6);
  EXPECT_GT(m.axis_spread, 0.3);
}

// Images drawn through the inverse of kdu (the scene renderer's model): the refinement in that
// model recovers the mount exactly; in ViSP's kud model (not kdu's exact inverse) it does not.
TEST(MountCalibration, RefinesInTheDistortionModelOfTheImages) {
  MountScene s = MakeMountScene(4);
  s.camera.kdu = 0.085;
  const std::vector<PatternDetection> detections =
      ExactDetections(s, DistortionModel::kInverseOfKdu);
  MountCalibrationOptions options = Options(s);
  options.distortion = DistortionModel::kInverseOfKdu;
  const MountCalibration m =
      CalibrateMountFromDetections(Names(s.angles.size()), s.angles, detections, s.camera, options);
  ASSERT_TRUE(m.ok()) << m.message;
  EXPECT_LT(PoseDelta(m.tilt_from_camera, s.tilt_from_camera).norm(), kExactPoseTol);
  EXPECT_LT(m.rms_px, 1e-6);
  const MountCalibration kud = CalibrateMountFromDetections(Names(s.angles.size()), s.angles,
                                                            detections, s.camera, Options(s));
  ASSERT_TRUE(kud.ok()) << kud.message;
  EXPECT_GT(kud.rms_px, 1e-3);
}

TEST(MountCalibration, NamesAViewTakenAtWrongAnglesAndLeavesItOut) {
  const MountScene s = MakeMountScene(5);
  std::vector<PatternDetection> detections = ExactDetections(s);
  for (PatternDetection& d : detections) {  // a little noise for a median error above zero
    std::mt19937 rng(9);
    std::normal_distribution<double> noise(0.0, 0.05);
    for (Eigen::Vector2d& p : d.image_points)
      p += Eigen::Vector2d(noise(rng), noise(rng));
  }
  std::vector<HeadAngles> angles = s.angles;
  angles[6].pan += 2.0 * M_PI / 180.0;  // logged 2 degrees off
  const MountCalibration m =
      CalibrateMountFromDetections(Names(angles.size()), angles, detections, s.camera, Options(s));
  ASSERT_TRUE(m.ok()) << m.message;
  EXPECT_EQ(m.views[6].status, ViewStatus::kOutlier);
  EXPECT_NE(m.views[6].reason.find("median"), std::string::npos) << m.views[6].reason;
  EXPECT_EQ(m.UsedViews(), static_cast<int>(angles.size()) - 1);
  EXPECT_EQ(m.rejection_rounds, 1);
  EXPECT_LT((m.tilt_from_camera.translation() - s.tilt_from_camera.translation()).norm(), 1e-3);
}

TEST(MountCalibration, HeadTurnedAboutOneAxisIsUnobservable) {
  const MountScene s = MakeMountScene(6);
  std::vector<HeadAngles> pan_only, tilt_only;
  std::vector<Eigen::Matrix3d> pans, tilts;
  for (int k = 0; k < 6; ++k) {
    pan_only.push_back({(-15.0 + 6.0 * k) * M_PI / 180.0, 0.1});
    tilt_only.push_back({0.05, (-10.0 + 4.0 * k) * M_PI / 180.0});
    pans.push_back(BaseFromTiltRotation(pan_only.back().pan, pan_only.back().tilt));
    tilts.push_back(BaseFromTiltRotation(tilt_only.back().pan, tilt_only.back().tilt));
  }
  EXPECT_LT(RotationAxisSpread(pans), 1e-6);
  EXPECT_LT(RotationAxisSpread(tilts), 1e-6);
  std::vector<Eigen::Matrix3d> grid;
  for (const HeadAngles& a : s.angles)
    grid.push_back(BaseFromTiltRotation(a.pan, a.tilt));
  EXPECT_GT(RotationAxisSpread(grid), 0.3);

  MountScene one_axis = s;
  one_axis.angles = pan_only;
  const MountCalibration m = CalibrateMountFromDetections(
      Names(pan_only.size()), pan_only, ExactDetections(one_axis), s.camera, Options(s));
  EXPECT_EQ(m.status, MountStatus::kUnobservable);
  EXPECT_NE(m.message.find("one axis"), std::string::npos) << m.message;
}

TEST(MountCalibration, BoardNeverFoundIsReported) {
  const MountScene s = MakeMountScene(7);
  const std::vector<PatternDetection> none(s.angles.size());
  const MountCalibration m =
      CalibrateMountFromDetections(Names(none.size()), s.angles, none, s.camera, Options(s));
  EXPECT_EQ(m.status, MountStatus::kPatternNeverFound);
  EXPECT_EQ(m.views[0].status, ViewStatus::kPatternNotFound);
}

TEST(Floor, HeightAndTiltFromTheLyingBoardsPose) {
  const MountScene s = MakeMountScene(8);
  for (double thickness : {0.0, 0.005}) {
    const FloorGeometry f = FloorFromBoardPose(s.base_from_floor_board, thickness);
    EXPECT_NEAR(f.crossing_height, s.crossing_height + thickness, kExactPoseTol);
    EXPECT_NEAR(f.base_roll, s.base_roll, kExactPoseTol);
    EXPECT_NEAR(f.base_pitch, s.base_pitch, kExactPoseTol);
  }
  // The whole floor calibration on the exact projection of the lying board.
  const Eigen::Isometry3d pose =
      CamFromBoard(s.tilt_from_camera, s.base_from_floor_board, s.floor_angles);
  BoardView view;
  for (const Eigen::Vector3d& p : BoardPoints(s.pattern)) {
    view.board_points.push_back(p);
    view.image_points.push_back(ProjectBoardPoint(s.camera, pose, p));
  }
  const FloorCalibration floor =
      CalibrateFloor(s.camera, view, s.floor_angles, s.tilt_from_camera,
                     Eigen::Matrix<double, 6, 6>::Identity() * 1e-8, 0.0);
  ASSERT_TRUE(floor.ok) << floor.failure;
  EXPECT_NEAR(floor.floor.crossing_height, s.crossing_height, kExactPoseTol);
  EXPECT_NEAR(floor.floor.base_roll, s.base_roll, kExactPoseTol);
  EXPECT_NEAR(floor.floor.base_pitch, s.base_pitch, kExactPoseTol);
  // A mount shifted 1e-4 m up moves the height by about as much: its variance shows through.
  EXPECT_GT(floor.covariance(0, 0), 0.5e-8);
}

class MountFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(LINETRACK_BINARY_DIR) / "test_output" / "MountFiles";
    std::filesystem::create_directories(dir_);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  std::filesystem::path dir_;
};

TEST_F(MountFiles, AnglesCsvAndItsErrors) {
  const std::string good =
      Write("angles.csv",
            "image,pan_deg,tilt_deg\n# comment\na/view_01.png,10,-5\nview_02.png, 0.5 ,2\n");
  const std::vector<AnglesRow> rows = ReadAnglesCsv(good);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NEAR(rows[0].angles.pan, 10.0 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(AnglesOfImage(rows, "/x/y/view_02.png", good).tilt, 2.0 * M_PI / 180.0, 1e-15);
  EXPECT_THROW(AnglesOfImage(rows, "view_03.png", good), InputError);
  for (const char* bad : {"image,pan,tilt\nv.png,1,2\n", "image,pan_deg,tilt_deg\nv.png,1\n",
                          "image,pan_deg,tilt_deg\nv.png,1,nan\n",
                          "image,pan_deg,tilt_deg\nv.png,1,2\nd/v.png,3,4\n"}) {
    EXPECT_THROW(ReadAnglesCsv(Write("bad.csv", bad)), InputError) << bad;
  }
  EXPECT_THROW(ReadAnglesCsv((dir_ / "missing.csv").string()), InputError);
}

TEST_F(MountFiles, MountJsonReadsBackAndEMcIsViSPs) {
  const MountScene s = MakeMountScene(9);
  MountCalibration m = CalibrateMountFromDetections(Names(s.angles.size()), s.angles,
                                                    ExactDetections(s), s.camera, Options(s));
  ASSERT_TRUE(m.ok()) << m.message;
  m.covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-8;
  MountRunInfo info;
  info.pattern = s.pattern;
  FloorCalibration floor;
  floor.ok = true;
  floor.floor = {1.25, 0.01, -0.02};
  info.floor = floor;
  const MountFile back = ReadMountFile(Write("mount.json", MountJson(m, info)));
  EXPECT_LT((back.tilt_from_camera.matrix() - m.tilt_from_camera.matrix()).norm(), 1e-15);
  EXPECT_LT((back.covariance - m.covariance).norm(), 1e-20);
  ASSERT_TRUE(back.floor.has_value());
  EXPECT_NEAR(back.floor->crossing_height, 1.25, 1e-15);
  EXPECT_NEAR(back.floor->base_pitch, -0.02, 1e-15);

  vpPoseVector pose;
  ASSERT_TRUE(vpPoseVector::loadYAML(Write("eMc.yaml", VispPoseYaml(m.tilt_from_camera)), pose));
  const vpHomogeneousMatrix eMc(pose);
  for (unsigned r = 0; r < 3; ++r)
    for (unsigned c = 0; c < 4; ++c)
      EXPECT_NEAR(eMc[r][c], m.tilt_from_camera.matrix()(r, c), 1e-12);

  for (const char* bad : {"{", "{\"tilt_from_camera\": [1,0,0]}",
                          "{\"tilt_from_camera\": [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "
                          "\"covariance\": {\"matrix\": []}, \"rms_px\": 0.1}"}) {
    EXPECT_THROW(ReadMountFile(Write("bad.json", bad)), InputError) << bad;
  }
}

}  // namespace
}  // namespace linetrack

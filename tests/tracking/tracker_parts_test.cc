// The tracker's small parts: settings files, pose files, health checks, priors and predictions,
// prior interpolation and ground-truth lookup, checked on hand-computed cases.
#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpPoseVector.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "models/cao_reader.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "tests/tracking/visp_data.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/relocalizer.h"
#include "tracking/tracker/robot_readings.h"
#include "tracking/tracker/sequence_tracker.h"
#include "tracking/tracker/tracker_settings.h"
#include "tracking/tracker/tracking_health.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

constexpr double kTol = 1e-9;

std::string WriteTemp(const std::string& name, const std::string& text) {
  const fs::path path =
      fs::temp_directory_path() / ("linetrack_parts_" + std::to_string(getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

TEST(TrackerSettings, ReadsTheSampleFileAsViSPDoes) {
  TrackerSettings base;
  base.passes = 3;
  const TrackerSettings s = ReadTrackerSettings(testing::Cube() + "/cube.xml", base);
  EXPECT_EQ(s.me.mask_size, 5);
  EXPECT_EQ(s.me.mask_count, 180);
  EXPECT_EQ(s.me.range, 7);
  EXPECT_DOUBLE_EQ(s.me.threshold, 5000.0);
  EXPECT_DOUBLE_EQ(s.me.mu1, 0.5);
  EXPECT_DOUBLE_EQ(s.me.sample_step, 4.0);
  EXPECT_DOUBLE_EQ(s.visibility.angle_appear_deg, 65.0);
  EXPECT_DOUBLE_EQ(s.visibility.angle_disappear_deg, 75.0);
  EXPECT_DOUBLE_EQ(s.visibility.near_clipping_m, 0.1);
  EXPECT_DOUBLE_EQ(s.visibility.far_clipping_m, 0.9);
  EXPECT_TRUE(s.visibility.fov_clipping);
  EXPECT_EQ(s.passes, 3);  // not part of ViSP's format: kept from the base
  EXPECT_EQ(s.source, testing::Cube() + "/cube.xml");
  std::string why;
  EXPECT_TRUE(TrackerSettings().Check(&why)) << why;
}

TEST(TrackerSettings, BadFilesAreInputErrors) {
  EXPECT_THROW(ReadTrackerSettings("/nonexistent/settings.xml"), InputError);
  const std::string malformed = WriteTemp("malformed.xml", "<conf><ecm><range>");
  EXPECT_THROW(ReadTrackerSettings(malformed), InputError);
  const std::string zero_range =
      WriteTemp("zero.xml", "<conf><ecm><range><tracking>0</tracking></range></ecm></conf>");
  try {
    ReadTrackerSettings(zero_range);
    ADD_FAILURE() << "a zero range was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(zero_range), std::string::npos) << e.what();
  }
  fs::remove(malformed);
  fs::remove(zero_range);
}

TEST(PoseFile, PoseVectorAndMatrixMatchViSP) {
  const vpPoseVector v(0.1, -0.2, 0.5, 2.1, 1.1, -0.45);
  const vpHomogeneousMatrix m(v);
  const Eigen::Isometry3d from_vector =
      ParsePoseText("0.1 -0.2 0.5\n2.1 1.1 -0.45\n", "vector.pos");
  std::string rows;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      rows += std::to_string(m[r][c]) + (c == 3 ? "\n" : " ");
  }
  const Eigen::Isometry3d from_matrix = ParsePoseText(rows, "matrix.txt");
  const Eigen::Isometry3d visp = FromVispPose(m);
  EXPECT_LT((from_vector.matrix() - visp.matrix()).norm(), 1e-12);
  EXPECT_LT((from_matrix.matrix() - visp.matrix()).norm(), 1e-5);  // 6 decimals written
  EXPECT_LT((FromVispPose(ToVispPose(from_vector)).matrix() - from_vector.matrix()).norm(), kTol);
}

TEST(PoseFile, MalformedPosesAreInputErrors) {
  EXPECT_THROW(ParsePoseText("1 2 3 4 5", "five.pos"), InputError);
  EXPECT_THROW(ParsePoseText("1 2 3 4 5 x", "word.pos"), InputError);
  EXPECT_THROW(ParsePoseText("1 2 3 4 5 nan", "nan.pos"), InputError);
  EXPECT_THROW(ParsePoseText("2 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1", "scaled.txt"), InputError);
  EXPECT_THROW(ParsePoseText("1 0 0 0  0 1 0 0  0 0 1 0  0 0 1 1", "row.txt"), InputError);
  EXPECT_THROW(ReadPoseFile("/nonexistent/cube.0.pos"), InputError);
}

TEST(Health, ComparePosesMeasuresCentreAndAngle) {
  const Eigen::Isometry3d a = CamFromWorld(RobotPose{1.0, 2.0, 0.3, 1.2, 0.1});
  const Eigen::Isometry3d b = CamFromWorld(RobotPose{1.0, 2.03, 0.3 + DegToRad(2.0), 1.2, 0.1});
  const PoseDifference d = ComparePoses(a, b);
  EXPECT_NEAR(d.translation, 0.03, kTol);
  EXPECT_NEAR(RadToDeg(d.rotation), 2.0, 1e-9);
}

TEST(Health, EachThresholdIsChecked) {
  const HealthThresholds limits;
  TrackHealth good;
  good.projection_error_deg = 5.0;
  good.edges_total = 200;
  good.edges_good = 180;
  EXPECT_EQ(HealthProblem(good, limits), "");
  TrackHealth h = good;
  h.projection_error_deg = 41.0;
  EXPECT_NE(HealthProblem(h, limits).find("projection error"), std::string::npos);
  h = good;
  h.edges_good = 20;
  EXPECT_NE(HealthProblem(h, limits).find("good moving edges"), std::string::npos);
  h = good;
  h.edges_good = 80;  // 0.4 of 200
  EXPECT_NE(HealthProblem(h, limits).find("0.40"), std::string::npos);
  h = good;
  h.position_sigma_m = 0.3;
  EXPECT_NE(HealthProblem(h, limits).find("position sigma"), std::string::npos);
  h = good;
  h.rotation_sigma_deg = std::nan("");
  EXPECT_NE(HealthProblem(h, limits).find("rotation sigma"), std::string::npos);
}

TEST(Health, RobotConstraintAndMotion) {
  RobotConstraint c;
  c.height = 1.3;
  c.tilt = DegToRad(5.0);
  EXPECT_EQ(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.35, DegToRad(6.0)}), c), "");
  EXPECT_NE(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.6, DegToRad(5.0)}), c), "");
  EXPECT_NE(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.3, DegToRad(12.0)}), c), "");
  Eigen::Isometry3d rolled = CamFromWorld(RobotPose{2, 3, 1.0, 1.3, DegToRad(5.0)});
  rolled.prerotate(Eigen::AngleAxisd(DegToRad(8.0), Eigen::Vector3d::UnitZ()));  // about the axis
  EXPECT_NE(ConstraintProblem(rolled, c).find("roll"), std::string::npos);
  // A known roll (the camera's mount): that roll passes, none or another does not.
  c.roll = DegToRad(8.0);
  EXPECT_EQ(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.3, DegToRad(5.0), c.roll}), c),
            "");
  EXPECT_NE(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.3, DegToRad(5.0)}), c), "");
  EXPECT_NE(ConstraintProblem(CamFromWorld(RobotPose{2, 3, 1.0, 1.3, DegToRad(5.0), -c.roll}), c),
            "");

  const MotionLimits limits;  // 5 m/s, 360 deg/s
  const Eigen::Isometry3d a = CamFromWorld(RobotPose{0, 0, 0, 1.3, 0});
  EXPECT_EQ(MotionProblem(a, CamFromWorld(RobotPose{0.1, 0, 0, 1.3, 0}), 0.1, limits), "");
  EXPECT_NE(MotionProblem(a, CamFromWorld(RobotPose{1.0, 0, 0, 1.3, 0}), 0.1, limits), "");
  EXPECT_NE(MotionProblem(a, CamFromWorld(RobotPose{0, 0, 1.0, 1.3, 0}), 0.1, limits), "");
}

TEST(Health, CovarianceSigmasAreTheLargestAxes) {
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  c.diagonal() << 1e-4, 4e-4, 9e-4, 1e-6, 2.5e-5, 4e-6;
  const Eigen::Vector2d s = CovarianceSigmas(c);
  EXPECT_NEAR(s.x(), 0.03, kTol);
  EXPECT_NEAR(s.y(), 0.005, kTol);
}

TEST(Relocalization, BoundsWidenAndStopAtTheirMaximum) {
  const RelocalizationOptions o;
  EXPECT_NEAR(WidenedBounds(0, o).delta_t, o.after_loss.delta_t, kTol);
  EXPECT_NEAR(WidenedBounds(4, o).delta_t, o.after_loss.delta_t + 4 * o.growth_t, kTol);
  EXPECT_NEAR(WidenedBounds(4, o).delta_phi, o.after_loss.delta_phi + 4 * o.growth_phi, kTol);
  EXPECT_NEAR(WidenedBounds(1000, o).delta_t, o.max.delta_t, kTol);
  EXPECT_NEAR(WidenedBounds(1000, o).delta_phi, o.max.delta_phi, kTol);
}

TEST(Relocalization, PriorCarriedByOdometryFollowsTheRelativeMotion) {
  // The odometry frame is the world turned by 30 degrees and shifted: the carried prior must be
  // the world pose of the same relative motion, whatever the odometry's drift.
  const RobotPose last_good{2.0, 1.0, DegToRad(10.0), 1.3, 0.05};
  const RobotPose odo_then{5.0, -1.0, DegToRad(40.0), 1.3, 0.05};
  // Robot drives 0.5 m forward and turns 20 degrees left in its own frame.
  const double h = odo_then.heading;
  const RobotPose odo_now{odo_then.x + 0.5 * std::cos(h), odo_then.y + 0.5 * std::sin(h),
                          h + DegToRad(20.0), 1.3, 0.07};
  const RobotPose carried = CarryPrior(last_good, odo_then, odo_now);
  EXPECT_NEAR(carried.x, 2.0 + 0.5 * std::cos(DegToRad(10.0)), kTol);
  EXPECT_NEAR(carried.y, 1.0 + 0.5 * std::sin(DegToRad(10.0)), kTol);
  EXPECT_NEAR(RadToDeg(carried.heading), 30.0, 1e-9);
  EXPECT_NEAR(carried.tilt, 0.07, kTol);
}

TEST(Relocalization, OdometryPredictionKeepsTheLastPoseRelation) {
  const RobotPose then{1.0, 2.0, 0.4, 1.3, 0.08}, now{1.2, 2.1, 0.5, 1.3, 0.1};
  // The last pose equal to the odometry's: the prediction is the odometry now.
  EXPECT_LT(
      (PredictFromOdometry(CamFromWorld(then), then, now).matrix() - CamFromWorld(now).matrix())
          .norm(),
      1e-12);
  // A last pose away from the odometry's: the prediction moves it by the odometry's motion in
  // the camera frame, C_now^-1 C_pred == C_then^-1 C_last.
  const Eigen::Isometry3d last = CamFromWorld(RobotPose{1.1, 2.05, 0.42, 1.32, 0.07});
  const Eigen::Isometry3d predicted = PredictFromOdometry(last, then, now);
  EXPECT_LT(((CamFromWorld(now).inverse() * predicted).matrix() -
             (CamFromWorld(then).inverse() * last).matrix())
                .norm(),
            1e-12);
}

TEST(RobotReadings, PriorsAreInterpolatedAlongTheShorterHeading) {
  std::vector<PriorRecord> r(2);
  r[0].t = 1.0;
  r[0].pose = RobotPose{0.0, 0.0, DegToRad(170.0), 1.2, 0.1};
  r[1].t = 2.0;
  r[1].pose = RobotPose{1.0, 2.0, DegToRad(-170.0), 1.4, 0.2};
  const std::optional<RobotPose> mid = InterpolatePrior(r, 1.25, 0.1);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->x, 0.25, kTol);
  EXPECT_NEAR(mid->y, 0.5, kTol);
  EXPECT_NEAR(RadToDeg(mid->heading), 175.0, 1e-9);
  EXPECT_NEAR(mid->height, 1.25, kTol);
  EXPECT_NEAR(mid->tilt, 0.125, kTol);
  EXPECT_TRUE(InterpolatePrior(r, 0.95, 0.1));
  EXPECT_FALSE(InterpolatePrior(r, 0.8, 0.1));
  EXPECT_FALSE(InterpolatePrior(r, 2.2, 0.1));
  EXPECT_FALSE(InterpolatePrior({}, 1.0, 0.1));
}

TEST(RobotReadings, GroundTruthIsTheNearestPoseWithinTolerance) {
  std::vector<StampedPose> poses(3);
  for (int i = 0; i < 3; ++i) {
    poses[i].t = 0.1 * i;
    poses[i].world_from_cam.translation() = Eigen::Vector3d(i, 0, 0);
  }
  const auto at = GroundTruthAt(poses, 0.13, 0.05);
  ASSERT_TRUE(at);
  EXPECT_NEAR(at->inverse().translation().x(), 1.0, kTol);  // cam_from_world of pose 1
  EXPECT_FALSE(GroundTruthAt(poses, 0.5, 0.05));
  EXPECT_NEAR(MedianTimeStep({0.0, 0.1, 0.2, 0.35}), 0.1, kTol);
  EXPECT_EQ(MedianTimeStep({1.0}), 0.0);
}

TEST(EdgeTracker, FrameLinesOnAWallCanBePulledAcrossThemselves) {
  // A wall x = 0 (normal +x), a door's jamb and lintel drawn on it as 3D lines, and a free line
  // in the air.
  CaoModel cao;
  cao.points = {{0, 0, 0},    {0, 4, 0},      {0, 4, 2.6}, {0, 0, 2.6}, {0, 1, 0},
                {0, 1, 2.05}, {0, 1.9, 2.05}, {1, 1, 1},   {1, 2, 1}};
  cao.faces = {{0, 1, 2, 3}};
  cao.lines = {{4, 5}, {5, 6}, {7, 8}};
  cao.face_names = {"wall"};
  cao.line_names = {"jamb", "lintel", "wire"};
  const WireframeModel model = WireframeModel::FromCao(cao);
  const std::vector<Eigen::Vector3d> directions = CasingDirections(model, 0.005);
  ASSERT_EQ(directions.size(), model.edges().size());
  for (const ModelEdge& edge : model.edges()) {
    const Eigen::Vector3d& u = directions[edge.id];
    if (edge.name == "jamb") {
      EXPECT_NEAR(std::abs(u.y()), 1.0, 1e-12) << "across a vertical jamb: along the wall";
    } else if (edge.name == "lintel") {
      EXPECT_NEAR(std::abs(u.z()), 1.0, 1e-12) << "across a lintel: vertical";
    } else {
      EXPECT_TRUE(u.isZero()) << edge.name << ": a face edge or a line on no face";
    }
  }
}

TEST(EdgeTracker, FailuresSpeakOfTheSettingsNotOfViSPsApi) {
  // ViSP 3.5's two forms of the message (vpMbEdgeTracker), with and without the counts.
  const std::string with_counts = TrackingFailureReason(
      "Not enough moving edges (12) to track the object: expected 38. Try to reduce the "
      "threshold=0.4 using setGoodMovingEdgesRatioThreshold()");
  EXPECT_EQ(with_counts.find("setGoodMovingEdgesRatioThreshold"), std::string::npos);
  EXPECT_NE(with_counts.find("(12 where 38 were needed)"), std::string::npos) << with_counts;
  EXPECT_NE(with_counts.find("<ecm><range><tracking>"), std::string::npos);
  EXPECT_NE(with_counts.find("<ecm><contrast><edge_threshold>"), std::string::npos);
  const std::string without_counts = TrackingFailureReason(
      "Not enough moving edges to track the object. Try to reduce the threshold=0.4 using "
      "setGoodMovingEdgesRatioThreshold()");
  EXPECT_EQ(without_counts.find("setGoodMovingEdgesRatioThreshold"), std::string::npos);
  EXPECT_EQ(without_counts.find("were needed"), std::string::npos);
  EXPECT_EQ(TrackingFailureReason("Moving edges not initialized"),
            "ViSP: Moving edges not initialized");
}

}  // namespace
}  // namespace linetrack

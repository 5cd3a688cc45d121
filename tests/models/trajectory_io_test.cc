// TUM and prior files: round trips and malformed input naming file and line.
#include "models/trajectory_io.h"

#include <gtest/gtest.h>

#include "models/errors.h"
#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kTumTol = 1e-8;    // 9 decimals written
constexpr double kPriorTol = 1e-6;  // 6 decimals written

// The message of the InputError `f` throws ("" when it does not throw).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryIo, TumRoundTrip) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 5; ++k) {
    const RobotPose pose{0.5 * k, 3.0 - k, DegToRad(40.0 * k - 90.0), 1.3, DegToRad(2.0 * k)};
    poses.push_back({0.1 * k, CamFromWorld(pose).inverse()});
  }
  const std::vector<StampedPose> back = ParseTum(FormatTum(poses), "mem.txt");
  ASSERT_EQ(back.size(), poses.size());
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(back[k].t, poses[k].t, kTumTol);
    EXPECT_LT((back[k].world_from_cam.matrix() - poses[k].world_from_cam.matrix()).norm(), kTumTol);
  }
}

TEST(TrajectoryIo, TumIsCameraInWorld) {
  // A camera at (1, 2, 1.5) with identity rotation: ViSP axes aligned with the world's.
  const std::vector<StampedPose> poses = ParseTum("# header\n\n0 1 2 1.5 0 0 0 1\n", "mem.txt");
  ASSERT_EQ(poses.size(), 1u);
  const Eigen::Vector3d centre = poses[0].world_from_cam * Eigen::Vector3d::Zero();
  EXPECT_NEAR((centre - Eigen::Vector3d(1, 2, 1.5)).norm(), 0.0, kTumTol);
}

TEST(TrajectoryIo, MalformedTumNamesFileAndLine) {
  EXPECT_NE(
      ErrorOf([] { ParseTum("0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 1\n", "a.txt"); }).find("a.txt:2:"),
      std::string::npos);
  EXPECT_NE(
      ErrorOf([] { ParseTum("# c\n0 0 0 x 0 0 0 1\n", "a.txt"); }).find("a.txt:2: not a number"),
      std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseTum("0 0 0 0 0 0 0 2\n", "a.txt"); }).find("a.txt:1: the quaternion"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ParseTum("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", "a.txt");
            }).find("a.txt:2: time does not increase"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseTum("0 nan 0 0 0 0 0 1\n", "a.txt"); }).find("a.txt:1:"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParseTum("# nothing\n", "a.txt"); }).find("no poses"), std::string::npos);
  EXPECT_NE(ErrorOf([] { ReadTum("/nonexistent/t.txt"); }).find("/nonexistent/t.txt"),
            std::string::npos);
}

TEST(TrajectoryIo, PriorsRoundTrip) {
  std::vector<PriorRecord> records;
  for (int k = 0; k < 4; ++k) {
    records.push_back(
        {0.25 * k, {1.0 + k, -2.0 * k, DegToRad(170.0 + 5.0 * k), 1.35, DegToRad(4.0)}});
  }
  const std::string text = FormatPriors(records);
  EXPECT_EQ(text.substr(0, text.find('\n')), kPriorCsvHeader);
  const std::vector<PriorRecord> back = ParsePriors(text, "p.csv");
  ASSERT_EQ(back.size(), records.size());
  for (size_t k = 0; k < records.size(); ++k) {
    EXPECT_NEAR(back[k].t, records[k].t, kPriorTol);
    EXPECT_NEAR(back[k].pose.x, records[k].pose.x, kPriorTol);
    EXPECT_NEAR(back[k].pose.y, records[k].pose.y, kPriorTol);
    EXPECT_NEAR(WrapAngle(back[k].pose.heading - records[k].pose.heading), 0.0, kPriorTol);
    EXPECT_NEAR(back[k].pose.height, records[k].pose.height, kPriorTol);
    EXPECT_NEAR(back[k].pose.tilt, records[k].pose.tilt, kPriorTol);
  }
}

TEST(TrajectoryIo, MalformedPriorsNameFileAndLine) {
  const std::string header = std::string(kPriorCsvHeader) + "\n";
  EXPECT_NE(
      ErrorOf([] { ParsePriors("t,x,y\n0,1,2\n", "p.csv"); }).find("p.csv:1: expected the header"),
      std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ParsePriors(header + "0,1,2,3,1.3,5\n0.1,1,2,3,1.3\n", "p.csv");
            }).find("p.csv:3: expected 6 numbers"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ParsePriors(header + "0,1,,3,1.3,5\n", "p.csv"); }).find("p.csv:2:"),
            std::string::npos);
  for (const char* height : {"-1", "0"}) {  // a camera height is above the floor
    EXPECT_NE(ErrorOf([&] {
                ParsePriors(header + "0,1,2,3," + height + ",5\n", "p.csv");
              }).find("p.csv:2: height"),
              std::string::npos);
  }
  EXPECT_NE(ErrorOf([&] {
              ParsePriors(header + "0,1,2,3,1,5\n0,1,2,3,1,5\n", "p.csv");
            }).find("p.csv:3: time does not increase"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ParsePriors("", "p.csv"); }).find("empty"), std::string::npos);
  EXPECT_EQ(ParsePriors(header, "p.csv").size(), 0u);  // a header alone: no records, valid
}

}  // namespace
}  // namespace linetrack

// The mount calibration on rendered views with a known truth (tests/support/mount_scene.h): a
// board standing still, seen at 20 head angles by a camera whose bracket is off the nominal
// PTU-46 mount by up to 5 mm and 1.5 deg per axis, rendered by ray casting through the lens'
// distortion with blur and sensor noise, then detected and calibrated as real images are; and the
// same board lying on the floor under a tilted base.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "calibration/floor_calibration.h"
#include "calibration/mount_calibration.h"
#include "models/geometry.h"
#include "tests/support/mount_scene.h"

namespace linetrack {
namespace {

using test_support::MakeMountScene;
using test_support::MountScene;
using test_support::RenderMountViews;

constexpr double kMountPositionTolM = 1e-3;   // the target: 1 mm
constexpr double kMountRotationTolDeg = 0.1;  // and 0.1 deg
constexpr double kFloorHeightTolM = 2e-3;     // and 2 mm
constexpr double kBaseTiltTolDeg = 0.1;
constexpr double kMaxRmsPx = 0.15;
constexpr int kNeesSeeds = 6;
// The mean NEES over the seeds, 6 for a consistent covariance: within a factor 3 either way (the
// chi-square bounds of 6 x 6 degrees of freedom are 0.5 and 1.7 times 6 at 99 %; the corners'
// errors are not independent Gaussians, so the margin is wider).
constexpr double kNeesLow = 2.0, kNeesHigh = 18.0;

BoardRenderOptions Render(std::uint64_t seed) {
  BoardRenderOptions options;
  options.blur_sigma = 0.6;
  options.noise_sigma = 2.0;
  options.seed = seed;
  return options;
}

struct CalibrationRun {
  MountScene scene;
  MountCalibration mount;
  FloorCalibration floor;
};

CalibrationRun Calibrate(std::uint64_t seed, bool with_floor) {
  CalibrationRun run;
  run.scene = MakeMountScene(seed);
  cv::Mat floor_image;
  const std::vector<cv::Mat> images =
      RenderMountViews(run.scene, Render(100 * seed), with_floor ? &floor_image : nullptr);
  MountCalibrationOptions options;
  options.pattern = run.scene.pattern;
  std::vector<PatternDetection> detections;
  std::vector<std::string> names;
  for (size_t i = 0; i < images.size(); ++i) {
    detections.push_back(DetectPattern(images[i], options.pattern, options.detection));
    names.push_back("view_" + std::to_string(i));
  }
  run.mount =
      CalibrateMountFromDetections(names, run.scene.angles, detections, run.scene.camera, options);
  if (with_floor && run.mount.ok()) {
    const PatternDetection d = DetectPattern(floor_image, options.pattern, options.detection);
    if (d.found) {
      run.floor = CalibrateFloor(
          run.scene.camera, ViewOfDetection("floor", d, BoardPoints(options.pattern)),
          run.scene.floor_angles, run.mount.tilt_from_camera, run.mount.covariance, 0.0);
    }
  }
  return run;
}

TEST(MountRendered, TwentyHeadAnglesGiveTheMountWithin1MmAnd01DegAndTheFloorWithin2Mm) {
  const CalibrationRun run = Calibrate(1, /*with_floor=*/true);
  ASSERT_TRUE(run.mount.ok()) << run.mount.message;
  EXPECT_EQ(run.mount.UsedViews(), 20);
  EXPECT_LT(run.mount.rms_px, kMaxRmsPx);
  const Eigen::Matrix<double, 6, 1> error =
      PoseDelta(run.mount.tilt_from_camera, run.scene.tilt_from_camera);
  std::printf("mount error %.3f mm, %.4f deg; sigma %.3f mm, %.4f deg; RMS %.3f px\n",
              1e3 * error.head<3>().norm(), RadToDeg(error.tail<3>().norm()),
              1e3 * std::sqrt(run.mount.covariance.topLeftCorner<3, 3>().trace()),
              RadToDeg(std::sqrt(run.mount.covariance.bottomRightCorner<3, 3>().trace())),
              run.mount.rms_px);
  const Eigen::Matrix<double, 6, 1> start =
      PoseDelta(run.mount.hand_eye_start, run.scene.tilt_from_camera);
  std::printf("ViSP's hand-eye start: %.3f mm, %.4f deg off\n", 1e3 * start.head<3>().norm(),
              RadToDeg(start.tail<3>().norm()));
  EXPECT_LT(error.head<3>().norm(), kMountPositionTolM);
  EXPECT_LT(RadToDeg(error.tail<3>().norm()), kMountRotationTolDeg);
  ASSERT_TRUE(run.floor.ok) << run.floor.failure;
  std::printf("floor height error %.3f mm (sigma %.3f mm), roll %.4f, pitch %.4f deg\n",
              1e3 * (run.floor.floor.crossing_height - run.scene.crossing_height),
              1e3 * std::sqrt(run.floor.covariance(0, 0)),
              RadToDeg(run.floor.floor.base_roll - run.scene.base_roll),
              RadToDeg(run.floor.floor.base_pitch - run.scene.base_pitch));
  EXPECT_NEAR(run.floor.floor.crossing_height, run.scene.crossing_height, kFloorHeightTolM);
  EXPECT_NEAR(RadToDeg(run.floor.floor.base_roll), RadToDeg(run.scene.base_roll), kBaseTiltTolDeg);
  EXPECT_NEAR(RadToDeg(run.floor.floor.base_pitch), RadToDeg(run.scene.base_pitch),
              kBaseTiltTolDeg);
}

// The normalised estimation error squared, e^T C^-1 e, of the mount across seeds.
TEST(MountRendered, ReportedCovarianceIsConsistentWithTheErrorsAcrossSeeds) {
  double sum = 0.0;
  for (int seed = 11; seed < 11 + kNeesSeeds; ++seed) {
    const CalibrationRun run = Calibrate(static_cast<std::uint64_t>(seed), /*with_floor=*/false);
    ASSERT_TRUE(run.mount.ok()) << "seed " << seed << ": " << run.mount.message;
    const Eigen::Matrix<double, 6, 1> e =
        PoseDelta(run.mount.tilt_from_camera, run.scene.tilt_from_camera);
    const double nees = e.dot(run.mount.covariance.ldlt().solve(e));
    std::printf("seed %d: error %.3f mm %.4f deg, NEES %.2f\n", seed, 1e3 * e.head<3>().norm(),
                RadToDeg(e.tail<3>().norm()), nees);
    sum += nees;
  }
  const double mean = sum / kNeesSeeds;
  std::printf("mean NEES %.2f (6 expected)\n", mean);
  EXPECT_GT(mean, kNeesLow);
  EXPECT_LT(mean, kNeesHigh);
}

}  // namespace
}  // namespace linetrack

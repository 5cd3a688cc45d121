// A pan-tilt head with a known camera mount looking at a board that stands still while the head
// turns, and at the same board lying on the floor: the ground truth of the mount calibration's
// tests (calibration/mount_calibration.h), rendered by tests/support/synthetic_board.h.
// Header-only: the calibration tests and the CLI tests share it.
#pragma once

#include <opencv2/core/mat.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

#include "calibration/mount_calibration.h"
#include "models/pan_tilt.h"
#include "tests/support/synthetic_board.h"

namespace linetrack::test_support {

struct MountScene {
  CameraIntrinsics camera;
  PatternSpec pattern;
  Eigen::Isometry3d tilt_from_camera;  // the true mount
  Eigen::Isometry3d base_from_board;   // the standing board
  std::vector<HeadAngles> angles;      // one view per entry
  // The floor: the base's tilt on it, the crossing's height, the lying board and its view.
  double base_roll = 0.0, base_pitch = 0.0, crossing_height = 0.0;
  Eigen::Isometry3d base_from_floor_board;
  HeadAngles floor_angles;
};

// The nominal PTU-46 mount (vpPtu46): upright, 0.0765 m left of and 0.068 m above the crossing.
inline Eigen::Isometry3d NominalPtuMount() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear().col(0) = Eigen::Vector3d(0.0, -1.0, 0.0);
  m.linear().col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);
  m.linear().col(2) = Eigen::Vector3d(1.0, 0.0, 0.0);
  m.translation() = Eigen::Vector3d(0.0, 0.0765, 0.068);
  return m;
}

// A 5 x 4 grid of pan within +-18 deg and tilt within +-10 deg.
inline std::vector<HeadAngles> GridAngles() {
  std::vector<HeadAngles> angles;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 5; ++c)
      angles.push_back({(-18.0 + 9.0 * c) * M_PI / 180.0, (-10.0 + 20.0 / 3.0 * r) * M_PI / 180.0});
  return angles;
}

inline Eigen::Isometry3d BaseFromTilt(const HeadAngles& a) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = BaseFromTiltRotation(a.pan, a.tilt);
  return t;
}

// cam_from_board of view `a` for a board at base_from_board.
inline Eigen::Isometry3d CamFromBoard(const Eigen::Isometry3d& tilt_from_camera,
                                      const Eigen::Isometry3d& base_from_board,
                                      const HeadAngles& a) {
  return (BaseFromTilt(a) * tilt_from_camera).inverse() * base_from_board;
}

// The scene of `seed`: the bracket off the nominal mount by up to 5 mm and 1.5 deg per axis, the
// board about 0.9 m in front of the head, the base tilted by up to 1 deg on the floor.
inline MountScene MakeMountScene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&rng](double a) { return std::uniform_real_distribution<double>(-a, a)(rng); };
  MountScene s;
  s.camera.width = 640;
  s.camera.height = 480;
  s.camera.px = s.camera.py = 500.0;
  s.camera.u0 = 321.0;
  s.camera.v0 = 239.0;
  s.camera.has_distortion = true;
  s.camera.kud = -0.08;
  s.pattern.cols = 9;
  s.pattern.rows = 6;
  s.pattern.square = 0.04;
  Eigen::Matrix<double, 6, 1> bracket;
  bracket << uniform(0.005), uniform(0.005), uniform(0.005), uniform(0.026), uniform(0.026),
      uniform(0.026);
  s.tilt_from_camera = MovedPose(NominalPtuMount(), bracket);
  // Facing the head: board x to the camera's right (-y), y down (-z), z away (+x); turned a bit.
  Eigen::Matrix3d facing;
  facing.col(0) = -Eigen::Vector3d::UnitY();
  facing.col(1) = -Eigen::Vector3d::UnitZ();
  facing.col(2) = Eigen::Vector3d::UnitX();
  s.base_from_board.linear() = RotationFromVector(Eigen::Vector3d(0.0, 0.0, 0.25 + uniform(0.05))) *
                               RotationFromVector(Eigen::Vector3d(0.0, 0.15, 0.0)) * facing;
  const Eigen::Vector3d half((s.pattern.cols - 1) * s.pattern.square / 2,
                             (s.pattern.rows - 1) * s.pattern.square / 2, 0.0);
  s.base_from_board.translation() =
      Eigen::Vector3d(0.9 + uniform(0.05), 0.07 + uniform(0.03), 0.06 + uniform(0.03)) -
      s.base_from_board.linear() * half;
  s.angles = GridAngles();
  // The floor: level_from_base = Ry(pitch) Rx(roll); the lying board 1.0 m ahead, 0.1 m left.
  s.base_roll = uniform(0.017);
  s.base_pitch = uniform(0.017);
  s.crossing_height = 0.95 + uniform(0.05);
  Eigen::Isometry3d level_from_base = Eigen::Isometry3d::Identity();
  level_from_base.linear() = LevelFromBaseRotation(s.base_roll, s.base_pitch);
  level_from_base.translation() = Eigen::Vector3d(0.0, 0.0, s.crossing_height);  // floor frame
  Eigen::Isometry3d floor_from_board = Eigen::Isometry3d::Identity();
  // Face up: board z down into the floor, x across (to the robot's right), y towards the robot.
  floor_from_board.linear().col(0) = -Eigen::Vector3d::UnitY();
  floor_from_board.linear().col(1) = -Eigen::Vector3d::UnitX();
  floor_from_board.linear().col(2) = -Eigen::Vector3d::UnitZ();
  floor_from_board.translation() =
      Eigen::Vector3d(1.05, 0.25, 0.0) + Eigen::Vector3d(0.0, 0.0, 0.0);
  s.base_from_floor_board = level_from_base.inverse() * floor_from_board;
  s.floor_angles = {0.0, 40.0 * M_PI / 180.0};
  return s;
}

// The views of the standing board (and, when `floor` is not null, the lying one) rendered with
// `options` (its seed offset per view).
inline std::vector<cv::Mat> RenderMountViews(const MountScene& s, BoardRenderOptions options,
                                             cv::Mat* floor = nullptr) {
  std::vector<cv::Mat> images;
  const std::uint64_t seed = options.seed;
  for (size_t i = 0; i < s.angles.size(); ++i) {
    options.seed = seed + i;
    images.push_back(RenderBoard(s.pattern, s.camera,
                                 CamFromBoard(s.tilt_from_camera, s.base_from_board, s.angles[i]),
                                 options));
  }
  if (floor != nullptr) {
    options.seed = seed + 1000;
    *floor = RenderBoard(s.pattern, s.camera,
                         CamFromBoard(s.tilt_from_camera, s.base_from_floor_board, s.floor_angles),
                         options);
  }
  return images;
}

}  // namespace linetrack::test_support

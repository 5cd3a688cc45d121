// The rendered drive of the ROS tests: the bundled hall, the wide camera with radial distortion,
// a robot driving the hall loop at 10 frames/s with the camera 1.3 m above its base, tilted 5
// degrees down, the head panning by `pan_amplitude`, 5 unmodelled objects; optionally the camera
// placed by the test (a camera on a head's calibrated mount).
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"

namespace linetrack::test {

constexpr double kSceneHeight = 1.3;  // camera above the base (m)
constexpr double kSceneTiltDeg = 5.0;
constexpr double kSceneStart = 1000.0;  // stamp of the first frame (s)
constexpr double kSceneStep = 0.1;      // seconds between frames

struct RenderedDrive {
  std::vector<SequenceFrame> frames;
  std::vector<vpImage<unsigned char>> images;
};

// The drive; `place_camera`, when given, replaces each frame's cam_from_world (its base, pan and
// tilt kept) before rendering.
inline RenderedDrive RenderHallDrive(
    int count, double pan_amplitude,
    const std::function<Eigen::Isometry3d(const SequenceFrame&)>& place_camera = nullptr) {
  const std::string source = LINETRACK_SOURCE_DIR;
  const WireframeModel model = WireframeModel::Load(source + "/models/hall.cao");
  const CameraIntrinsics camera = ReadCameraXml(source + "/tests/data/camera_wide.xml");
  NavigableAreaOptions nav;
  nav.sidecar_path = source + "/tests/data/hall.nav.json";
  const NavigableArea area = NavigableArea::FromModel(model, nav);
  DriveOptions drive;
  drive.frames = count;
  drive.fps = 1.0 / kSceneStep;
  drive.height = kSceneHeight;
  drive.tilt = DegToRad(kSceneTiltDeg);
  drive.pan_amplitude = pan_amplitude;
  RenderedDrive r;
  r.frames = DriveAlongLoop(LoopInsideArea(area), drive);
  if (place_camera) {
    for (SequenceFrame& frame : r.frames)
      frame.cam_from_world = place_camera(frame);
  }
  RenderOptions render;
  render.scene.clutter = 5;
  SceneRenderer renderer(model, camera, render, &area);
  for (int i = 0; i < count; ++i)
    r.images.push_back(renderer.Render(r.frames[i].cam_from_world, i));
  return r;
}

// The x, y, yaw block (rows and columns 0, 1, 5) of a ROS pose covariance.
inline Eigen::Matrix3d PlanarBlock(const Eigen::Matrix<double, 6, 6>& c) {
  const int k[3] = {0, 1, 5};
  Eigen::Matrix3d b;
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 3; ++j)
      b(r, j) = c(k[r], k[j]);
  return b;
}

inline sensor_msgs::Image ImageMsg(const vpImage<unsigned char>& image, const ros::Time& stamp) {
  sensor_msgs::Image msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "camera_optical";
  msg.width = image.getWidth();
  msg.height = image.getHeight();
  msg.encoding = "mono8";
  msg.step = msg.width;
  msg.data.assign(image.bitmap, image.bitmap + image.getSize());
  return msg;
}

// The camera's CameraInfo (plumb_bob with k1 = ViSP's kud).
inline sensor_msgs::CameraInfo CameraInfoOf(const CameraIntrinsics& camera) {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "camera_optical";
  info.width = camera.width;
  info.height = camera.height;
  info.K = {camera.px, 0.0, camera.u0, 0.0, camera.py, camera.v0, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {camera.has_distortion ? camera.kud : 0.0, 0.0, 0.0, 0.0, 0.0};
  return info;
}

}  // namespace linetrack::test

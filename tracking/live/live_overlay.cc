#include "tracking/live/live_overlay.h"

#include <visp3/core/vpFont.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpImageDraw.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "models/geometry.h"

namespace linetrack {
namespace {

vpImagePoint Point(const Eigen::Vector2d& uv) {
  return vpImagePoint(uv.y(), uv.x());  // ViSP: (row, column)
}

// Draws the undistorted segment a-b on the distorted image, in pieces of about 8 pixels.
void DrawDistortedSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                          const CameraIntrinsics& camera, const vpColor& color,
                          vpImage<vpRGBa>* image) {
  const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 8.0)));
  Eigen::Vector2d previous = camera.Distort(a);
  for (int k = 1; k <= pieces; ++k) {
    const Eigen::Vector2d next = camera.Distort(a + (b - a) * (static_cast<double>(k) / pieces));
    vpImageDraw::drawLine(*image, Point(previous), Point(next), color, 1);
    previous = next;
  }
}

}  // namespace

vpImage<vpRGBa> DrawLiveOverlay(const vpImage<unsigned char>& frame, const LiveIteration& it,
                                const std::vector<ProjectedEdge>& edges,
                                const CameraIntrinsics& camera, const Eigen::Vector2d& desired_px) {
  vpImage<vpRGBa> image;
  vpImageConvert::convert(frame, image);
  for (const ProjectedEdge& edge : edges) {
    DrawDistortedSegment(edge.image.a, edge.image.b, camera, vpColor::green, &image);
  }
  vpImageDraw::drawCross(image, Point(camera.Distort(desired_px)), 15, vpColor::blue, 1);
  if (it.has_target && it.estimate.has_pose()) {
    const Eigen::Vector3d seen = *it.estimate.cam_from_world * it.target;
    if (seen.z() > 0.0) {
      const Eigen::Vector2d uv = camera.Distort(camera.Undistorted().Project(seen));
      vpImageDraw::drawCircle(image, Point(uv), 6, vpColor::red, 2);
    }
  }
  char text[200];
  std::snprintf(text, sizeof(text),
                "t %.2f s  %s [%s, %s]  pan %.2f tilt %.2f deg  error %.1f px%s", it.t,
                ToString(it.estimate.uncertainty.status), ToString(it.estimate.status),
                it.estimate.source.c_str(), RadToDeg(it.head.pan), RadToDeg(it.head.tilt),
                it.servo.error_px, it.servo.converged ? "  converged" : "");
  const vpFont font(14, vpFont::GENERIC_MONOSPACE);
  font.drawText(image, text, vpImagePoint(4, 4), vpColor::yellow, vpColor::black);
  return image;
}

}  // namespace linetrack

// Whether a rendered frame lets a tracker see the model: the model edges whose visible,
// unoccluded image pieces are long enough, from the true pose and what the renderer drew.
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "models/camera.h"
#include "models/occlusion.h"
#include "models/render/render_scene.h"
#include "models/render/scene_renderer.h"
#include "models/wireframe.h"

namespace linetrack {

struct ObservabilityOptions {
  double min_edge_px = 40.0;      // an edge counts when one visible piece is at least this long
  int min_edges = 3;              // a frame is observable with at least this many such edges
  double occluder_margin = 0.02;  // metres (+ 1 % of the depth): how much nearer than an edge
                                  // point an unmodelled surface must be to hide it

  bool Check(std::string* why) const;
};

// What one frame shows.
struct FrameObservation {
  int edges = 0;                // model edges with a visible piece >= min_edge_px
  bool observable = false;      // edges >= min_edges
  double people_share = 0.0;    // share of the pixels that show a person
  double clutter_share = 0.0;   // share of the pixels that show unmodelled clutter
  double centre_depth_m = 0.0;  // depth along the optical axis at the image centre (0: none)
};

// Projects the model edges seen from `cam_from_world` with `camera` (undistorted pinhole, the
// image size given) through ProjectVisibleEdges (the model's faces hide them), then samples each
// visible piece along the edge and drops the samples that the renderer's `seen` map shows behind
// an unmodelled surface (clutter, people) nearer than the edge point by the margin. An edge's
// length is its longest run of unhidden samples, in pixels. `scene` gives the surfaces' kinds.
FrameObservation ObserveFrame(const WireframeModel& model, const OcclusionTester& occlusion,
                              const CameraIntrinsics& camera,
                              const Eigen::Isometry3d& cam_from_world, const SurfaceMap& seen,
                              const RenderScene& scene, const ObservabilityOptions& options = {});

}  // namespace linetrack

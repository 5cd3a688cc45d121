// Key views (seed 002, "model views"): the line segments of an image taken from a known pose,
// each with the id of the 3D line it images (a model edge id, or a track id where no model
// exists), and its junctions: points where the images of two such lines meet at a shared
// 3D point. A set of key views of one camera forms a view database. docs/views.md.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "matching/views/tokens.h"
#include "models/camera.h"
#include "models/geometry.h"
#include "models/navigable_area.h"
#include "models/occlusion.h"
#include "models/robot_pose.h"
#include "models/wireframe.h"

namespace linetrack {

// One segment of a key view.
struct ViewSegment {
  Segment2 image;    // undistorted pixels
  int line_id = -1;  // the 3D line it images, shared by every view; -1 unknown
};

// A point seen in a key view as the meeting of lines' images.
struct ViewJunction {
  int point_id = -1;  // the 3D point (a model vertex id), shared by every view
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted pixels
  std::vector<int> lines;  // ids of the lines (at least two) whose images meet there
};

struct KeyView {
  int id = -1;
  RobotPose pose;  // the camera's pose when the view was taken
  std::vector<ViewSegment> segments;
  std::vector<ViewJunction> junctions;

  std::vector<Segment2> Images() const;
};

// Key views of one camera with what matching them needs.
struct ViewDatabase {
  CameraIntrinsics camera;  // undistorted model: every pixel of the views is undistorted
  std::string model_path;   // the model the line ids refer to (empty: ids are track ids)
  TokenOptions token_options;
  TokenEqualisation equalisation;
  std::vector<KeyView> views;
  std::vector<std::vector<Token>> tokens;  // per view, derived (ComputeViewTokens)
};

// Fits the equalisation on the views' own segments and computes every view's tokens.
void ComputeViewTokens(ViewDatabase* db);

struct KeyViewOptions {
  double min_length_px = 20.0;           // shorter edge images are dropped
  double min_junction_angle_deg = 20.0;  // two lines meeting at a narrower angle make no junction
  double vertex_tolerance_m = 1e-6;      // an edge's visible piece ends at a vertex within this

  bool Check(std::string* why) const;
};

// A key view from the visible pieces of the model's edges seen from `pose` (models/occlusion.h
// ProjectVisibleEdges with the undistorted camera): each piece a segment with its edge id; a
// junction at every vertex where two visible pieces end, their images at least
// min_junction_angle_deg apart (the widest such pair).
KeyView KeyViewFromEdges(const WireframeModel& model, const std::vector<ProjectedEdge>& pieces,
                         const RobotPose& pose, const KeyViewOptions& options);

// Every junction of the visible pieces: each model vertex where pieces of two or more edges end
// with images at least min_junction_angle_deg apart, with the ids of every edge ending there;
// the pixel is the pieces' common image endpoint.
std::vector<ViewJunction> VertexJunctions(const WireframeModel& model,
                                          const std::vector<ProjectedEdge>& pieces,
                                          const KeyViewOptions& options);

// The poses of `views build --grid`: positions every `step` metres over the navigable area's
// bounding box that the area contains, each with headings every `heading_step` from 0.
struct ViewGrid {
  double step = 1.0;                     // metres
  double heading_step = DegToRad(30.0);  // radians
  double height = 1.3;                   // metres
  double tilt = DegToRad(5.0);           // radians, positive looking down

  bool Check(std::string* why) const;
};
std::vector<RobotPose> GridPoses(const NavigableArea& area, const ViewGrid& grid);

}  // namespace linetrack

// Detected segments judged against the truth: the visible model edges projected with the true
// pose (models/occlusion.h ProjectVisibleEdges). Which edges were found, how far the detected
// endpoints are from the projected ones, and which detections image which model edge.
#pragma once

#include <string>
#include <vector>

#include <visp3/core/vpImage.h>
#include <Eigen/Geometry>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/render/scene_renderer.h"

namespace linetrack {

// When a detection images a projected model edge, and when the edge counts as found.
struct DetectionMatchOptions {
  double max_angle_deg = 2.0;  // between a detection and the projected edge
  double max_offset_px = 2.0;  // both endpoints of the detection from the edge's line
  double end_margin_px = 5.0;  // a detection this far past the edge's ends still touches it
  double min_coverage = 0.5;   // share of the edge's length its detections must cover

  bool Check(std::string* why) const;
};

// True when `detection` lies along `edge` (both in undistorted pixels): angle and offset within
// the options, and part of it within the edge's ends +- end_margin_px.
bool DetectionOnEdge(const Segment2& edge, const Segment2& detection,
                     const DetectionMatchOptions& options);

// Share of `edge`'s length covered by the union of the detections' projections onto it.
double EdgeCoverage(const Segment2& edge, const std::vector<Segment2>& detections);

// One piece of model edge judged against the detections.
struct EdgeDetection {
  int edge_id = -1;
  Segment2 edge;                // projected visible piece (undistorted pixels)
  std::vector<int> detections;  // indices of the detections lying along it
  double coverage = 0.0;        // share of the piece covered by them
  bool found = false;           // coverage >= min_coverage
  // For each end of the piece, distance (pixels) to the nearest endpoint of its detections;
  // measured when found and the end is a true end of the edge's image (a vertex, the image
  // border, occlusion by the model), not where its contrast fades.
  double endpoint_error[2] = {0.0, 0.0};
  bool end_measured[2] = {false, false};
};

// A piece of a visible model edge that an image can show, and which of its ends are ends of
// the visible edge itself (not made by fading contrast or by clutter in front).
struct ObservablePiece {
  ProjectedEdge edge;
  bool true_end[2] = {true, true};
};

// The judging of one image: its pieces and the figures over the found ones.
struct DetectionEvaluation {
  std::vector<EdgeDetection> edges;  // the pieces at least min_edge_length_px long
  int found = 0;
  std::vector<double> endpoint_errors;  // of the measured ends of the found pieces
  // Line noise of the detections along found pieces: perpendicular distance of each detected
  // endpoint from the piece's line (pixels), angle between detection and piece (degrees).
  std::vector<double> offsets_px, angle_errors_deg;
};

// Judges `detections` against the pieces of model edges `truth` that project at least
// `min_edge_length_px` long (the visible pieces: every end measured; or observable ones).
DetectionEvaluation EvaluateDetections(const std::vector<ObservablePiece>& truth,
                                       const std::vector<Segment2>& detections,
                                       double min_edge_length_px,
                                       const DetectionMatchOptions& options);
DetectionEvaluation EvaluateDetections(const std::vector<ProjectedEdge>& truth,
                                       const std::vector<Segment2>& detections,
                                       double min_edge_length_px,
                                       const DetectionMatchOptions& options);

// For each detection, the model edge ids along whose visible pieces (any length) it lies: the
// true correspondences of an image (several ids when model edges are collinear in the image).
std::vector<std::vector<int>> TrueCorrespondences(const std::vector<ProjectedEdge>& truth,
                                                  const std::vector<Segment2>& detections,
                                                  const DetectionMatchOptions& options);

// The parts of `edges` (undistorted pixels) that the image can show: sampled every 2 px, a
// sample counts when the surface seen there is not clutter nearer than the edge (`surfaces`)
// and `clean` (noise-free render, distorted as the camera distorts) steps by `min_contrast`
// across it; runs of counting samples (gaps of one sample bridged) become pieces.
std::vector<ObservablePiece> ObservablePieces(const std::vector<ProjectedEdge>& edges,
                                              const vpImage<unsigned char>& clean,
                                              const SurfaceMap& surfaces, const RenderScene& scene,
                                              const CameraIntrinsics& camera,
                                              const Eigen::Isometry3d& cam_from_world,
                                              double min_contrast);

}  // namespace linetrack

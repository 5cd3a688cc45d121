// ViSP's model-based moving-edge tracker (vpMbGenericTracker, EDGE features) behind a small
// interface: start from a pose, track a frame, measure its health. ViSP's exceptions stop here:
// a failed call is a result with a reason. Images must be undistorted (ImageUndistorter).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/geometry.h"
#include "models/occlusion.h"
#include "models/wireframe.h"
#include "tracking/tracker/tracker_settings.h"
#include "tracking/tracker/tracking_health.h"

class vpMbGenericTracker;

namespace linetrack {

// The outcome of Start() or Track().
struct EdgeTrackResult {
  bool ok = false;     // false: ViSP failed (reason says why); the pose is then meaningless
  std::string reason;  // why ViSP failed when !ok (TrackingFailureReason)
  Eigen::Isometry3d cam_from_world = Eigen::Isometry3d::Identity();  // cMo after the call
  // ViSP's own pose before the sub-pixel refinement (equal to cam_from_world without it).
  Eigen::Isometry3d visp_cam_from_world = Eigen::Isometry3d::Identity();
  TrackHealth health;       // measured by Track() (Start() measures nothing)
  double passes_ms = 0.0;   // Track(): wall clock in ViSP's track() calls
  double measure_ms = 0.0;  // Track(): projection error read, moving-edge states, refinement,
                            // covariance
  // Track() with the sub-pixel refinement applied: its edges and points (the measurements of the
  // pose, for tracking/integrity/) and the edges it set aside.
  std::vector<EdgeObservation> observations;
  std::vector<EdgeObservation> set_aside;
};

// RMS image motion (pixels) of the model `edges` (world) between two poses: the edges are clipped
// to the view of `from`, their clipped ends projected under both poses. 0 when no edge is in view;
// infinite when an end falls behind the camera at `to`.
double RmsImageMotionPx(const std::vector<Segment3>& edges, const CameraIntrinsics& camera,
                        const Eigen::Isometry3d& from, const Eigen::Isometry3d& to);

class EdgeTracker {
 public:
  // Reads the .cao model (linetrack's reader orients its faces), hands ViSP the oriented model
  // (LoadOrientedVispModel) and applies `settings` and the (undistorted) camera, whose image size
  // must be known. Throws InputError naming the model when it cannot be loaded, or naming the
  // settings' source when they are invalid.
  EdgeTracker(const std::string& model_path, const CameraIntrinsics& camera,
              const TrackerSettings& settings);
  ~EdgeTracker();
  EdgeTracker(const EdgeTracker&) = delete;
  EdgeTracker& operator=(const EdgeTracker&) = delete;

  // (Re)starts the tracker at `cam_from_world` on `image`: the moving edges are sampled there.
  EdgeTrackResult Start(const vpImage<unsigned char>& image,
                        const Eigen::Isometry3d& cam_from_world);

  // Tracks `image` from the current pose (settings.passes passes) and measures the health. The pose
  // covariance only `with_covariance`: ViSP computes it with a dense n x n weight matrix over the n
  // moving edges, which costs several times the tracking. Needs a successful Start() since the last
  // failure.
  // With `known` (a robot's height and tilt) the refined pose respects them (3 unknowns).
  EdgeTrackResult Track(const vpImage<unsigned char>& image, bool with_covariance = false,
                        const std::optional<KnownHeightTilt>& known = std::nullopt);

  // Aligns `predicted` (e.g. the last pose moved by the robot's odometry) on the edges of `image`
  // (EdgeAlignmentOptions of the settings) and starts the tracker there; Track() then follows.
  // Not ok when too few edges are found near the predicted model.
  EdgeTrackResult StartFromPrediction(const vpImage<unsigned char>& image,
                                      const Eigen::Isometry3d& predicted,
                                      const std::optional<KnownHeightTilt>& known = std::nullopt);

  // RmsImageMotionPx of this tracker's model edges (undistorted camera).
  double ImageMotionPx(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) const {
    return RmsImageMotionPx(edges_, camera_, from, to);
  }
  // True after a successful Start() and until a Track() fails.
  bool started() const { return started_; }

  const TrackerSettings& settings() const { return settings_; }
  const CameraIntrinsics& camera() const { return camera_; }

 private:
  EdgeTrackResult Measure(const vpImage<unsigned char>& image, bool with_covariance,
                          const std::optional<KnownHeightTilt>& known);

  std::unique_ptr<vpMbGenericTracker> tracker_;
  std::unique_ptr<WireframeModel> model_;  // linetrack's reading of the model
  std::unique_ptr<OcclusionTester> occlusion_;
  std::vector<Segment3> edges_;  // the model's edges (world), for the sub-pixel refinement
  std::vector<Eigen::Vector3d> casing_directions_;  // per edge (CasingDirections)
  CameraIntrinsics camera_;
  TrackerSettings settings_;
  bool started_ = false;
};

// Per model edge (ids of model.edges()): for a free 3D line drawn on a face (a door or window
// frame line), the unit direction on that face across the line, n_face x (B - A) normalised, in
// which a casing may lie beside it; zero for face edges and lines on no face (within
// `tolerance_m` of the plane and of the face's extent).
std::vector<Eigen::Vector3d> CasingDirections(const WireframeModel& model, double tolerance_m);

// Moving edges after a ViSP track() call (its display features: {0, i, j, state} per site):
// how many there are, and the image positions (u, v) of the good ones (vpMeSite::NO_SUPPRESSION).
struct MovingEdgeSites {
  int total = 0;
  std::vector<Eigen::Vector2d> good;
};
MovingEdgeSites ReadMovingEdgeSites(const std::vector<std::vector<double>>& features);

// cam_from_world <-> ViSP's cMo.
vpHomogeneousMatrix ToVispPose(const Eigen::Isometry3d& cam_from_world);
Eigen::Isometry3d FromVispPose(const vpHomogeneousMatrix& cMo);

// Applies `settings` (moving edges, visibility, iterations) and the camera to a ViSP tracker;
// also used to configure the bare ViSP baseline of `linetrack bench track`.
void ConfigureVispTracker(const TrackerSettings& settings, const CameraIntrinsics& camera,
                          vpMbGenericTracker* tracker);

// Loads a .cao model into a ViSP tracker without ViSP's console output. Throws InputError naming
// the file when ViSP cannot load it.
void LoadVispModel(const std::string& model_path, vpMbGenericTracker* tracker);

// Loads `model` (built from `cao`) into a ViSP tracker with its faces as linetrack oriented them
// (through a temporary .cao file, models/cao_writer.h); an object left as written loads from its
// own file. Throws InputError naming the model when ViSP cannot load it.
void LoadOrientedVispModel(const CaoModel& cao, const WireframeModel& model,
                           vpMbGenericTracker* tracker);

// Why ViSP's tracker failed, in the user's terms. ViSP's "not enough moving edges ... Try to reduce
// the threshold=R using setGoodMovingEdgesRatioThreshold()" names an API call; this says what
// failed and which keys of the tracker settings file find more moving edges. Other messages
// come back as "ViSP: message".
std::string TrackingFailureReason(const std::string& visp_message);

}  // namespace linetrack

#include "tracking/tracker/edge_tracker.h"

#include "models/silence_stdout.h"

#include <visp3/core/vpEigenConversion.h>
#include <visp3/core/vpException.h>
#include <visp3/mbt/vpMbGenericTracker.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>

#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "models/cao_reader.h"
#include "models/cao_writer.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/text_format.h"
#include "models/wireframe.h"
#include "tracking/tracker/casing_evidence.h"

namespace linetrack {

namespace {

// ViSP's vpMeSite::NO_SUPPRESSION: a moving edge found and kept.
constexpr double kGoodSiteState = 0.0;
constexpr double kNearClip = 0.05;  // metres, for the image motion of the model
// A frame line lies on its face within this (metres).
constexpr double kCasingPlaneToleranceM = 0.005;

using Clock = std::chrono::steady_clock;

}  // namespace

double RmsImageMotionPx(const std::vector<Segment3>& edges, const CameraIntrinsics& camera,
                        const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  double sum = 0.0;
  int count = 0;
  for (const Segment3& edge : edges) {
    Segment3 clipped = edge;
    if (!ClipToFrustum(from, camera, kNearClip, &clipped)) continue;
    for (const Eigen::Vector3d& end : {clipped.a, clipped.b}) {
      const Eigen::Vector3d at_from = from * end, at_to = to * end;
      if (!(at_to.z() > 0.0)) return std::numeric_limits<double>::infinity();
      sum += (camera.Project(at_to) - camera.Project(at_from)).squaredNorm();
      ++count;
    }
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

MovingEdgeSites ReadMovingEdgeSites(const std::vector<std::vector<double>>& features) {
  MovingEdgeSites sites;
  for (const std::vector<double>& feature : features) {
    if (feature.size() < 4 || feature[0] != 0.0) continue;  // type 0: a moving edge
    ++sites.total;
    if (feature[3] == kGoodSiteState) sites.good.emplace_back(feature[2], feature[1]);
  }
  return sites;
}

vpHomogeneousMatrix ToVispPose(const Eigen::Isometry3d& cam_from_world) {
  vpHomogeneousMatrix cMo;
  vp::eigen2visp(Eigen::MatrixXd(cam_from_world.matrix()), cMo);
  return cMo;
}

Eigen::Isometry3d FromVispPose(const vpHomogeneousMatrix& cMo) {
  Eigen::Matrix4d m;
  vp::visp2eigen(cMo, m);
  return Eigen::Isometry3d(m);
}

void LoadVispModel(const std::string& model_path, vpMbGenericTracker* tracker) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(model_path, ec)) {
    throw InputError(Located(model_path, 0, "cannot read the model file"));
  }
  try {
    ScopedStdoutSilencer silence;
    tracker->loadModel(model_path, /*verbose=*/false);
  } catch (const vpException& e) {
    throw InputError(
        Located(model_path, 0, std::string("ViSP cannot load the model: ") + e.getMessage()));
  }
}

void LoadOrientedVispModel(const CaoModel& cao, const WireframeModel& model,
                           vpMbGenericTracker* tracker) {
  if (!model.oriented()) {
    LoadVispModel(model.path(), tracker);
    return;
  }
  // ViSP reads models from files only: a private temporary file, removed once read.
  std::string path =
      (std::filesystem::temp_directory_path() / "linetrack-oriented-XXXXXX.cao").string();
  const int fd = mkstemps(path.data(), 4);
  if (fd < 0)
    throw InputError(Located(model.path(), 0, "cannot write the oriented model for ViSP"));
  close(fd);
  struct Remove {
    std::string path;
    ~Remove() {
      std::error_code ec;
      std::filesystem::remove(path, ec);
    }
  } remove{path};
  std::ofstream(path) << CaoText(OrientedCao(cao, model), model.path() + ", faces oriented");
  try {
    LoadVispModel(path, tracker);
  } catch (const InputError& e) {
    throw InputError(Located(model.path(), 0, std::string("oriented copy: ") + e.what()));
  }
}

void ConfigureVispTracker(const TrackerSettings& settings, const CameraIntrinsics& camera,
                          vpMbGenericTracker* tracker) {
  std::string why;
  if (!settings.Check(&why)) throw InputError(Located(settings.source, 0, why));
  vpMe me;
  me.setMaskSize(static_cast<unsigned>(settings.me.mask_size));
  me.setMaskNumber(static_cast<unsigned>(settings.me.mask_count));
  me.setRange(static_cast<unsigned>(settings.me.range));
  me.setThreshold(settings.me.threshold);
  me.setMu1(settings.me.mu1);
  me.setMu2(settings.me.mu2);
  me.setSampleStep(settings.me.sample_step * settings.pass_step_factor);
  tracker->setMovingEdge(me);
  vpCameraParameters cam;
  cam.initPersProjWithoutDistortion(camera.px, camera.py, camera.u0, camera.v0);
  tracker->setCameraParameters(cam);
  const VisibilitySettings& v = settings.visibility;
  tracker->setAngleAppear(vpMath::rad(v.angle_appear_deg));
  tracker->setAngleDisappear(vpMath::rad(v.angle_disappear_deg));
  tracker->setNearClippingDistance(v.near_clipping_m);
  tracker->setFarClippingDistance(v.far_clipping_m);
  unsigned clipping = vpMbtPolygon::NEAR_CLIPPING | vpMbtPolygon::FAR_CLIPPING;
  if (v.fov_clipping) clipping |= vpMbtPolygon::FOV_CLIPPING;
  tracker->setClipping(clipping);
  tracker->setScanLineVisibilityTest(v.scanline);
  tracker->setMaxIter(static_cast<unsigned>(settings.max_iterations));
  // ViSP records the state of each moving edge (found, rejected and why) only for display;
  // linetrack reads it for the share of good moving edges.
  tracker->setDisplayFeatures(true);
  tracker->setGoodMovingEdgesRatioThreshold(settings.good_edge_ratio);
}

std::vector<Eigen::Vector3d> CasingDirections(const WireframeModel& model, double tolerance_m) {
  std::vector<Eigen::Vector3d> out(model.edges().size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < model.edges().size(); ++i) {
    const ModelEdge& edge = model.edges()[i];
    if (!edge.from_line || edge.face >= 0) continue;
    const Eigen::Vector3d a = edge.segment.a, b = edge.segment.b;
    for (const ModelFace& face : model.faces()) {
      if (face.Degenerate() || face.corners.empty()) continue;
      if (std::abs(face.normal.dot(a) - face.offset) > tolerance_m ||
          std::abs(face.normal.dot(b) - face.offset) > tolerance_m) {
        continue;
      }
      Eigen::AlignedBox3d extent;
      for (const Eigen::Vector3d& c : face.corners)
        extent.extend(c);
      extent.min().array() -= tolerance_m;
      extent.max().array() += tolerance_m;
      if (!extent.contains(a) || !extent.contains(b)) continue;
      const Eigen::Vector3d across = face.normal.cross(b - a);
      if (across.norm() > 0.0) out[i] = across.normalized();
      break;
    }
  }
  return out;
}

EdgeTracker::EdgeTracker(const std::string& model_path, const CameraIntrinsics& camera,
                         const TrackerSettings& settings)
    : tracker_(std::make_unique<vpMbGenericTracker>(1, vpMbGenericTracker::EDGE_TRACKER)),
      camera_(camera.Undistorted()),
      settings_(settings) {
  if (camera_.width <= 0 || camera_.height <= 0) {
    throw InputError("camera '" + camera_.name + "': the image size is needed to track");
  }
  const CaoModel cao = ReadCao(model_path);
  model_ = std::make_unique<WireframeModel>(WireframeModel::FromCao(cao));
  LoadOrientedVispModel(cao, *model_, tracker_.get());
  occlusion_ = std::make_unique<OcclusionTester>(*model_);
  for (const ModelEdge& edge : model_->edges())
    edges_.push_back(edge.segment);
  casing_directions_ = CasingDirections(*model_, kCasingPlaneToleranceM);
  try {
    ConfigureVispTracker(settings_, camera_, tracker_.get());
  } catch (const vpException& e) {
    throw InputError(
        Located(settings_.source, 0, std::string("ViSP rejects the settings: ") + e.getMessage()));
  }
}

EdgeTracker::~EdgeTracker() = default;

EdgeTrackResult EdgeTracker::Start(const vpImage<unsigned char>& image,
                                   const Eigen::Isometry3d& cam_from_world) {
  EdgeTrackResult result;
  started_ = false;
  try {
    tracker_->initFromPose(image, ToVispPose(cam_from_world));
    result.ok = true;
    result.cam_from_world = FromVispPose(tracker_->getPose());
    started_ = true;
  } catch (const vpException& e) {
    result.reason = TrackingFailureReason(e.getMessage());
  }
  return result;
}

EdgeTrackResult EdgeTracker::StartFromPrediction(const vpImage<unsigned char>& image,
                                                 const Eigen::Isometry3d& predicted,
                                                 const std::optional<KnownHeightTilt>& known) {
  std::vector<Segment3> visible;
  for (const ProjectedEdge& edge : ProjectVisibleEdges(*model_, *occlusion_, predicted, camera_))
    visible.push_back(edge.world);
  const EdgeRefinement aligned =
      AlignToEdges(image, camera_, visible, {predicted, known}, settings_.alignment);
  if (!aligned.applied) {
    started_ = false;
    EdgeTrackResult result;
    result.reason = "too few image edges near the predicted pose (" +
                    std::to_string(aligned.points) + " points)";
    return result;
  }
  return Start(image, aligned.cam_from_world);
}

EdgeTrackResult EdgeTracker::Track(const vpImage<unsigned char>& image, bool with_covariance,
                                   const std::optional<KnownHeightTilt>& known) {
  EdgeTrackResult result;
  if (!started_) {
    result.reason = "the tracker has not been started";
    return result;
  }
  try {
    const Clock::time_point start = Clock::now();
    int passes = 0;
    for (; passes < settings_.passes; ++passes) {
      const bool last = passes + 1 == settings_.passes;
      tracker_->setProjectionErrorComputation(last);
      tracker_->setMaxIter(static_cast<unsigned>(last || settings_.first_passes_max_iterations == 0
                                                     ? settings_.max_iterations
                                                     : settings_.first_passes_max_iterations));
      tracker_->setDisplayFeatures(last);
      tracker_->setCovarianceComputation(last && with_covariance);
      tracker_->track(image);
    }
    const double passes_ms = MillisecondsSince(start);
    const Clock::time_point measure_start = Clock::now();
    EdgeTrackResult measured = Measure(image, with_covariance, known);
    measured.health.passes = passes;
    measured.passes_ms = passes_ms;
    measured.measure_ms = MillisecondsSince(measure_start);
    return measured;
  } catch (const vpException& e) {
    started_ = false;
    result.reason = TrackingFailureReason(e.getMessage());
    return result;
  }
}

EdgeTrackResult EdgeTracker::Measure(const vpImage<unsigned char>& image, bool with_covariance,
                                     const std::optional<KnownHeightTilt>& known) {
  EdgeTrackResult result;
  result.ok = true;
  result.cam_from_world = FromVispPose(tracker_->getPose());
  result.visp_cam_from_world = result.cam_from_world;
  TrackHealth& health = result.health;
  health.projection_error_deg = tracker_->getProjectionError();
  const MovingEdgeSites sites = ReadMovingEdgeSites(tracker_->getFeaturesForDisplay());
  health.edges_total = sites.total;
  health.edges_good = static_cast<int>(sites.good.size());
  if (settings_.refine_subpixel) {
    EdgeRefinement refined = RefineOnEdges(image, camera_, edges_, sites.good,
                                           {result.cam_from_world, known}, settings_.refinement);
    health.refined = refined.applied;
    health.refined_points = refined.points;
    health.refinement_refusal = refined.refusal;
    if (refined.applied) {
      result.cam_from_world = refined.cam_from_world;
      health.refined_rms_before_px = refined.rms_before_px;
      health.refined_rms_after_px = refined.rms_after_px;
      health.refined_rejected_edges = refined.rejected_edges;
      health.refined_position_sigma_m = refined.position_sigma_m;
      health.refined_heading_sigma_deg = RadToDeg(refined.heading_sigma_rad);
      result.observations = std::move(refined.observations);
      for (EdgeObservation& o : result.observations) {
        if (o.model_edge >= 0 && o.model_edge < static_cast<int>(casing_directions_.size()))
          o.casing_direction = casing_directions_[o.model_edge];
      }
      // A frame line pays the casing allowance unless the image shows it has no casing.
      ClearCasingsNotSeen(image, camera_, result.cam_from_world, CasingEvidenceOptions(),
                          &result.observations);
      result.set_aside = std::move(refined.set_aside);
    }
  }
  if (!with_covariance) return result;
  const vpMatrix covariance = tracker_->getCovarianceMatrix();
  if (covariance.getRows() == 6 && covariance.getCols() == 6) {
    Eigen::Matrix<double, 6, 6> c;
    for (int r = 0; r < 6; ++r) {
      for (int k = 0; k < 6; ++k)
        c(r, k) = covariance[r][k];
    }
    const Eigen::Vector2d sigmas = CovarianceSigmas(c);
    health.position_sigma_m = sigmas.x();
    health.rotation_sigma_deg = vpMath::deg(sigmas.y());
  }
  return result;
}

std::string TrackingFailureReason(const std::string& visp_message) {
  if (visp_message.rfind("Not enough moving edges", 0) != 0) return "ViSP: " + visp_message;
  // "Not enough moving edges (N) to track the object: expected M. Try to reduce ..." (or
  // without the counts): N good moving edges, M needed.
  std::string counts;
  const size_t open = visp_message.find('('), expected = visp_message.find("expected ");
  if (open != std::string::npos && expected != std::string::npos) {
    const std::string found = visp_message.substr(open + 1, visp_message.find(')') - open - 1);
    const size_t end = visp_message.find_first_not_of("0123456789", expected + 9);
    counts = " (" + found + " where " + visp_message.substr(expected + 9, end - expected - 9) +
             " were needed)";
  }
  return "too few moving edges found the model's edges in the image" + counts +
         ": the pose is off or the edges are faint; a larger <ecm><range><tracking> or a lower "
         "<ecm><contrast><edge_threshold> in the tracker settings file finds more";
}

}  // namespace linetrack

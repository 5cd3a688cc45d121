// The pose covariance and integrity of the sub-pixel refinement on rendered frames of the bundled
// hall (`render --path hall-loop`: wide camera with barrel distortion, 10 unmodelled objects,
// 10 frames/s): each frame is tracked once by ViSP's moving edges and the refinement from a start
// 2 cm and 0.3 degree off the truth, and the integrity monitor's pose and covariance are scored
// against the truth (NEES, the 99 % region, protection levels).
#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <random>

#include "models/navigable_area.h"
#include "models/render/scene_renderer.h"
#include "models/render/sequence.h"
#include "tracking/integrity/consistency.h"
#include "tracking/integrity/integrity_monitor.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/image_undistorter.h"

namespace linetrack {
namespace {

constexpr int kFrames = 60;  // 6 s along the loop
const std::string kSource = LINETRACK_SOURCE_DIR;
// On these frames (figures in docs/integrity.md, section 4) the default edge noise model's 99.9 %
// region holds at least this share of the truths, its median sigma is within this factor of the
// median error (issue 14: 3), most poses are tracking and none is beyond its protection levels.
constexpr double kMin999Share = 0.95;
constexpr double kMaxSigmaToError = 3.0;
constexpr int kMinTracking = 45;
// Points taken as independent are overconfident: their 99 % region holds fewer truths.
constexpr double kMaxNaive99Share = 0.9;

struct HallFrames {
  WireframeModel model = WireframeModel::Load(kSource + "/models/hall.cao");
  CameraIntrinsics camera = ReadCameraXml(kSource + "/tests/data/camera_wide.xml");
  std::vector<SequenceFrame> frames;
  std::vector<vpImage<unsigned char>> images;

  HallFrames() {
    NavigableAreaOptions nav;
    nav.sidecar_path = kSource + "/tests/data/hall.nav.json";
    const NavigableArea area = NavigableArea::FromModel(model, nav);
    DriveOptions drive;
    drive.frames = kFrames;
    frames = DriveAlongLoop(LoopInsideArea(area), drive);
    RenderOptions render;
    render.scene.clutter = 10;
    SceneRenderer renderer(model, camera, render, &area);
    for (int i = 0; i < kFrames; ++i)
      images.push_back(renderer.Render(frames[i].cam_from_world, i));
  }
};

const HallFrames& Hall() {
  static const HallFrames data;
  return data;
}

// One frame's measurements: the refinement's edges and points after ViSP's moving edges.
struct Measured {
  bool ok = false;
  Eigen::Isometry3d refined = Eigen::Isometry3d::Identity();
  std::vector<EdgeObservation> observations;
};

std::vector<Measured> MeasureFrames() {
  const HallFrames& hall = Hall();
  ImageUndistorter undistorter(hall.camera);
  EdgeTracker tracker(kSource + "/models/hall.cao", hall.camera, TrackerSettings());
  std::mt19937 random(31);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Measured> out;
  for (int i = 0; i < kFrames; ++i) {
    const vpImage<unsigned char>& image = undistorter.Apply(hall.images[i]);
    const RobotPose& truth = hall.frames[i].camera;
    WorldTwist offset = WorldTwist::Zero();
    offset << 0.015 * normal(random), 0.015 * normal(random), 0.0, 0.0, 0.0,
        DegToRad(0.3) * normal(random);
    Measured m;
    if (tracker.Start(image, ApplyWorldTwist(hall.frames[i].cam_from_world, offset)).ok) {
      const EdgeTrackResult r =
          tracker.Track(image, false, KnownHeightTilt{truth.height, truth.tilt});
      m.ok = r.ok && r.health.refined;
      m.refined = r.cam_from_world;
      m.observations = r.observations;
    }
    out.push_back(std::move(m));
  }
  return out;
}

const std::vector<Measured>& Measurements() {
  static const std::vector<Measured> data = MeasureFrames();
  return data;
}

struct HallFigures {
  CalibrationSummary pose, position, heading;  // NEES of (x, y, heading), (x, y), heading
  int tracking = 0, degraded = 0, lost = 0, integrity_failures = 0;
};

// The monitor on every measured frame with `options`; NEES with the reported (fault-aware)
// covariance, or the fault-free one.
HallFigures Score(const IntegrityOptions& options, bool fault_aware = true) {
  const HallFrames& hall = Hall();
  const CameraIntrinsics camera = hall.camera.Undistorted();
  CalibrationTally pose(3), position(2), heading(1);
  HallFigures f;
  for (int i = 0; i < kFrames; ++i) {
    const Measured& m = Measurements()[i];
    if (!m.ok) {
      ++f.lost;
      continue;
    }
    const RobotPose& truth = hall.frames[i].camera;
    const PoseParameterisation parameters(KnownHeightTilt{truth.height, truth.tilt});
    const PoseIntegrity p =
        EvaluatePoseIntegrity(m.observations, camera, m.refined, parameters, options);
    f.tracking += p.status == IntegrityStatus::kTracking;
    f.degraded += p.status == IntegrityStatus::kDegraded;
    f.lost += p.status == IntegrityStatus::kLost;
    if (p.status == IntegrityStatus::kLost) continue;
    const Eigen::VectorXd e =
        parameters.Difference(p.solution.cam_from_world, hall.frames[i].cam_from_world);
    const Eigen::MatrixXd& covariance = fault_aware ? p.covariance : p.solution.covariance;
    const Eigen::Vector2d sigmas = LargestSigmas(parameters, covariance);
    pose.Add(Nees(e, covariance), sigmas[0], e.head<2>().norm());
    position.Add(Nees(e.head<2>(), covariance.topLeftCorner<2, 2>()), sigmas[0],
                 e.head<2>().norm());
    heading.Add(e[2] * e[2] / covariance(2, 2), RadToDeg(sigmas[1]), RadToDeg(std::abs(e[2])));
    f.integrity_failures +=
        p.status == IntegrityStatus::kTracking &&
        (e.head<2>().norm() > p.levels.position_m || std::abs(e[2]) > p.levels.rotation_rad);
  }
  f.pose = pose.Summary();
  f.position = position.Summary();
  f.heading = heading.Summary();
  return f;
}

void Print(const std::string& label, const HallFigures& f) {
  std::cout << label << ": tracking " << f.tracking << ", degraded " << f.degraded << ", lost "
            << f.lost << ", integrity failures " << f.integrity_failures << "\n"
            << f.pose.Table(label + ", x y heading", "m") << f.position.Row(label + ", x y") << "\n"
            << f.heading.Row(label + ", heading") << " (deg)\n";
}

// The rendered frames' camera, height and tilt are exact: no consider parameters.
IntegrityOptions RenderedTruth() {
  IntegrityOptions options;
  options.solver.considered = ConsideredUncertainty{0.0, 0.0, 0.0, 0.0, 0.0};
  return options;
}

// The default edge noise model on the rendered frames (exact camera, height and tilt): the 99.9 %
// region holds the truths, the median sigma is within 3x the median error, most poses are
// tracking and none is beyond its protection levels. The default uncertainties of the camera and
// mount (not in the rendered data), considered or estimated with the pose, widen the covariance
// and the protection levels: no tracking pose is beyond them either, and estimating them widens
// less (docs/integrity.md, section 1.4), so more poses are tracking.
TEST(IntegrityHall, DefaultNoiseModelIsCalibratedAndKeepsIntegrity) {
  const HallFigures f = Score(RenderedTruth());
  Print("default edge noise", f);
  EXPECT_GE(f.pose.shares[3], kMin999Share);
  EXPECT_LE(f.pose.median_sigma, kMaxSigmaToError * f.pose.median_error);
  EXPECT_EQ(f.integrity_failures, 0);
  EXPECT_GE(f.tracking, kMinTracking);
  using Handling = ConsideredUncertainty::Handling;
  std::map<Handling, HallFigures> by_handling;
  for (const Handling handling : {Handling::kConsider, Handling::kEstimate}) {
    IntegrityOptions options;
    options.solver.considered.intrinsics = options.solver.considered.mount = handling;
    const HallFigures& defaults = by_handling[handling] = Score(options);
    Print(handling == Handling::kEstimate ? "default uncertainties, estimated"
                                          : "default uncertainties, considered",
          defaults);
    EXPECT_EQ(defaults.integrity_failures, 0);
    EXPECT_GE(defaults.pose.shares[3], kMin999Share);
  }
  EXPECT_GT(by_handling[Handling::kEstimate].tracking, by_handling[Handling::kConsider].tracking);
  EXPECT_LT(by_handling[Handling::kEstimate].pose.median_sigma,
            by_handling[Handling::kConsider].pose.median_sigma);
}

// Simpler models (docs/integrity.md, sections 1.5 and 4) are overconfident on the same frames:
// independent points (no edge-level error, no fault hypotheses) leave the truth outside their
// 99 % region far more often than 1 % and report poses beyond their protection levels; without
// model error the 99.9 % region holds fewer truths than the defaults'; without averaging over the
// fault hypotheses the NEES is larger; 5 mm of model error widens the covariance further.
TEST(IntegrityHall, SimplerNoiseModelsAreOverconfident) {
  const HallFigures defaults = Score(RenderedTruth());
  IntegrityOptions naive = RenderedTruth();
  naive.solver.noise.model_sigma_m = 0.0;
  naive.solver.noise.latch_sigma_px = 0.0;
  naive.solver.noise.estimate_edge_scale = false;
  naive.edge_fault_probability = 0.0;
  const HallFigures independent = Score(naive);
  Print("independent points", independent);
  EXPECT_LE(independent.pose.shares[2], kMaxNaive99Share);
  EXPECT_GT(independent.integrity_failures, 0);
  IntegrityOptions no_model = RenderedTruth();
  no_model.solver.noise.model_sigma_m = 0.0;
  no_model.solver.noise.latch_sigma_px = 0.3;
  const HallFigures without_model = Score(no_model);
  Print("no model error, 0.3 px latch", without_model);
  EXPECT_LT(without_model.pose.shares[3], defaults.pose.shares[3]);
  const HallFigures fault_free = Score(RenderedTruth(), false);
  Print("fault-free covariance", fault_free);
  EXPECT_GT(fault_free.pose.mean_nees, defaults.pose.mean_nees);
  IntegrityOptions wider = RenderedTruth();
  wider.solver.noise.model_sigma_m = 0.005;
  wider.solver.noise.latch_sigma_px = 0.3;
  const HallFigures wide = Score(wider);
  Print("5 mm model error, 0.3 px latch", wide);
  EXPECT_GT(wide.pose.median_sigma, defaults.pose.median_sigma);
}

}  // namespace
}  // namespace linetrack

#include "app/render_sequence.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/cli_common.h"
#include "models/errors.h"
#include "models/geometry.h"
#include "models/render/drive_renderer.h"
#include "models/render/png.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

constexpr double kDriftWindowM = 10.0;  // metres of the odometry drift windows

double Milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// The camera file as ViSP writes it, placed atomically.
void WriteCameraAtomically(const std::string& path, const CameraIntrinsics& camera) {
  const std::string tmp = path + ".tmp.xml";
  WriteCameraXml(tmp, camera, "<generator>linetrack render</generator>");
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path + ": cannot write the file");
  }
}

std::vector<SequenceFrame> GeneratedFrames(const RenderSequenceOptions& opt,
                                           const NavigableArea* area) {
  DriveOptions drive = opt.drive;
  drive.frames = opt.frames;
  drive.height = opt.height;
  drive.tilt = DegToRad(opt.tilt_deg);
  drive.tilt_amplitude = DegToRad(opt.tilt_amplitude_deg);
  drive.pan_amplitude = DegToRad(opt.pan_amplitude_deg);
  drive.pan_rate = DegToRad(opt.pan_rate_deg);
  std::string why;
  if (!drive.Check(&why)) throw InputError("--path: " + why);
  if (area == nullptr) throw InputError("--path: a generated path needs the navigable area");
  if (opt.path == kHallLoopPath) return DriveAlongLoop(LoopInsideArea(*area, opt.loop), drive);
  const SampledPath path = PathThroughWaypoints(ReadWaypoints(opt.path), opt.waypoints, opt.path);
  CheckPathInsideArea(path, *area, opt.path);
  try {
    return DriveAlongPath(path, drive);
  } catch (const InputError& e) {
    throw InputError(opt.path + ": " + e.what());
  }
}

nlohmann::ordered_json EffectsJson(const RenderedSequence& s) {
  nlohmann::ordered_json people = nlohmann::ordered_json::array();
  for (size_t k = 0; k < s.effects.people.size(); ++k) {
    const PersonWalk& w = s.effects.people[k];
    people.push_back({{"crossing_t", s.effects.person_crossing_t[k]},
                      {"t_start", w.t_start},
                      {"t_end", w.t_end},
                      {"start", {w.start.x(), w.start.y()}},
                      {"velocity", {w.velocity.x(), w.velocity.y()}},
                      {"height", w.height}});
  }
  nlohmann::ordered_json blackouts = nlohmann::ordered_json::array();
  for (const auto& [start, end] : s.effects.blackouts)
    blackouts.push_back({start, end});
  nlohmann::ordered_json gain = nlohmann::ordered_json::array();
  for (const GainKnot& k : s.effects.gain)
    gain.push_back({k.t, k.gain});
  return {{"people", people},
          {"blackouts", blackouts},
          {"gain_knots", gain},
          {"shutter_s", s.effects_options.shutter}};
}

nlohmann::ordered_json SequenceJson(const RenderedSequence& s, int observable) {
  nlohmann::ordered_json drift = {
      {"asked_percent", s.drift_asked > 0.0 ? nlohmann::ordered_json(100.0 * s.drift_asked)
                                            : nlohmann::ordered_json(nullptr)},
      {"window_m", s.drift.window_m},
      {"windows", s.drift.windows},
      {"max_percent", 100.0 * s.drift.max_share},
      {"mean_percent", 100.0 * s.drift.mean_share},
      {"whole_run_percent", 100.0 * s.drift.whole_share}};
  nlohmann::ordered_json kidnaps = nlohmann::ordered_json::array();
  for (const Kidnap& k : s.kidnaps) {
    kidnaps.push_back({{"frame", k.frame},
                       {"put_down", {k.put_down.x, k.put_down.y, RadToDeg(k.put_down.heading)}}});
  }
  return {{"frames", s.frames.size()},
          {"duration_s", s.frames.empty() ? 0.0 : s.frames.back().t - s.frames.front().t},
          {"observable_frames", observable},
          {"odometry_drift", drift},
          {"kidnaps", kidnaps},
          {"effects", EffectsJson(s)}};
}

}  // namespace

void CheckSequenceFlags(RenderSequenceOptions* options) {
  const RenderSequenceOptions& o = *options;
  options->kidnaps.clear();
  for (const std::string& text : o.kidnap_texts)
    options->kidnaps.push_back(ParseKidnap(text));
  CheckRange(o.pan_amplitude_deg, -180.0, 180.0, "--pan-amplitude");
  CheckRange(o.pan_rate_deg, 0.0, 720.0, "--pan-rate");
  CheckRange(o.odometry_drift_percent, 0.0, 40.0, "--odometry-drift");
  CheckRange(o.effects.shutter, 0.0, 1.0, "--shutter");
  CheckRange(o.effects.blackout_duration, 0.001, 60.0, "--blackout-duration");
  if (o.effects.people < 0 || o.effects.blackouts < 0 || o.effects.exposure_changes < 0) {
    throw InputError("--people, --blackouts, --exposure-changes: must be >= 0");
  }
  if (o.path.empty() || o.path == kHallLoopPath) return;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.path, ec)) {
    throw InputError("--path: '" + o.path + "' is neither " + kHallLoopPath +
                     " nor a waypoint file");
  }
  std::string why;
  if (!o.waypoints.Check(&why)) throw InputError("--corner-radius: " + why);
}

RenderedSequence PrepareSequence(const RenderSequenceOptions& opt, const NavigableArea* area) {
  RenderedSequence s;
  if (!opt.trajectory.empty()) {
    s.frames = FramesFromTrajectory(ReadTum(opt.trajectory));
    if (opt.frames > 0 && static_cast<size_t>(opt.frames) < s.frames.size())
      s.frames.resize(opt.frames);
  } else {
    s.frames = GeneratedFrames(opt, area);
  }
  OdometryOptions odometry;
  odometry.seed = opt.seed;
  if (opt.drift_given) {
    s.drift_asked = opt.odometry_drift_percent / 100.0;
    odometry = OdometryForDrift(s.drift_asked, opt.seed);
  }
  s.priors = SimulateOdometryPriors(s.frames, odometry);
  s.drift = MeasureOdometryDrift(s.frames, s.priors, kDriftWindowM);
  s.kidnaps = opt.kidnaps;
  s.frames = ApplyKidnaps(std::move(s.frames), s.kidnaps, opt.trajectory.empty() ? area : nullptr);
  s.effects_options = opt.effects;
  s.effects_options.seed = opt.seed;
  s.effects = PlanDriveEffects(s.frames, s.effects_options, area);
  if (static_cast<int>(s.effects.people.size()) < opt.effects.people) {
    spdlog::warn("{} of {} people fit in front of the camera", s.effects.people.size(),
                 opt.effects.people);
  }
  return s;
}

void WriteSequence(const std::string& out, const WireframeModel& model, SceneRenderer* renderer,
                   bool undistorted, RenderedSequence* sequence) {
  EnsureDirectory(out);
  const std::filesystem::path dir(out);
  const size_t count = sequence->frames.size();
  DriveRenderer drive(model, renderer, sequence->frames, sequence->effects,
                      sequence->effects_options);
  std::vector<FrameTruth> truth;
  std::vector<double> render_ms, total_ms;
  int observable = 0;
  const size_t report_every = std::max<size_t>(1, count / 10);
  for (size_t f = 0; f < count; ++f) {
    const auto start = std::chrono::steady_clock::now();
    DriveRenderer::Rendered frame = drive.RenderFrame(f);
    render_ms.push_back(Milliseconds(std::chrono::steady_clock::now() - start));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05zu.png", f);
    WriteFileAtomically((dir / name).string(), EncodePng(frame.image));
    total_ms.push_back(Milliseconds(std::chrono::steady_clock::now() - start));
    observable += frame.truth.observable;
    truth.push_back(frame.truth);
    if ((f + 1) % report_every == 0 || f + 1 == count) {
      spdlog::info("rendered {}/{} frames", f + 1, count);
    }
  }
  const CameraIntrinsics& camera = renderer->camera();
  WriteFileAtomically((dir / "groundtruth.txt").string(),
                      FormatTum(GroundTruthPoses(sequence->frames)));
  WriteFileAtomically((dir / "priors.csv").string(), FormatPriors(sequence->priors));
  WriteFileAtomically((dir / "frame_truth.csv").string(), FormatFrameTruth(truth));
  WriteFileAtomically((dir / "sequence.json").string(),
                      SequenceJson(*sequence, observable).dump(2) + "\n");
  WriteCameraAtomically((dir / "camera.xml").string(), undistorted ? camera.Undistorted() : camera);
  std::cout << "wrote " << count << " frames (" << camera.width << "x" << camera.height << ") to "
            << out << ": median " << std::fixed << std::setprecision(1)
            << QuantileNearestRank(render_ms, 0.5) << " ms per frame to render and judge, "
            << QuantileNearestRank(total_ms, 0.5) << " ms with PNG encoding and writing; "
            << observable << " observable; odometry drift " << std::setprecision(2)
            << 100.0 * sequence->drift.whole_share << " % over the run, "
            << 100.0 * sequence->drift.max_share << " % at most over " << kDriftWindowM << " m"
            << std::endl;
}

}  // namespace linetrack::app

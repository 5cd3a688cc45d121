#include "app/bench/track_bench.h"

#include <visp3/core/vpException.h>
#include <visp3/mbt/vpMbGenericTracker.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>

#include "models/errors.h"
#include "models/text_format.h"
#include "tracking/capture/video_source.h"
#include "tracking/tracker/edge_tracker.h"
#include "tracking/tracker/pose_file.h"
#include "tracking/tracker/sequence_tracker.h"

namespace linetrack::app {

namespace {

using Clock = std::chrono::steady_clock;

// CPU time of the calling thread (milliseconds): robust to other processes on a shared machine.
double ThreadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

bool Exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}

std::vector<vpImage<unsigned char>> LoadFrames(const std::string& pattern) {
  VideoSource source(pattern, VideoSourceOptions());
  std::vector<vpImage<unsigned char>> frames;
  Frame frame;
  while (source.Grab(&frame) == FrameStatus::kOk)
    frames.push_back(frame.image);
  if (frames.size() < 2) throw InputError(pattern + ": fewer than two frames");
  return frames;
}

// A sequence from ViSP's data: frames, model, settings file, start pose file.
std::optional<BenchSequence> Sequence(const std::string& name, const std::string& folder,
                                      const std::string& images, const std::string& model,
                                      const std::string& settings, const std::string& start) {
  if (!Exists(folder + "/" + settings) || !Exists(model) || !Exists(folder + "/" + start)) {
    return std::nullopt;
  }
  BenchSequence s;
  s.name = name;
  s.images = folder + "/" + images;
  s.model = model;
  s.visp_settings = folder + "/" + settings;
  s.camera = ReadCameraXml(s.visp_settings);
  s.start = ReadPoseFile(folder + "/" + start);
  TrackerSettings base;
  base.visibility.scanline = false;  // convex objects and a free camera: nothing to hide
  s.settings = ReadTrackerSettings(s.visp_settings, base);
  return s;
}

}  // namespace

std::string CastleSimuSceneCao(const std::string& castle_folder) {
  return "V1\n"
         "load(\"" +
         castle_folder +
         "/Models/chateau.cao\")\n"
         "load(\"" +
         castle_folder +
         "/Models/cube.cao\", t=[-0.2; 0.12; -0.15], "
         "tu=[0; 2.221441469079183; 2.221441469079183])\n"
         "0\n0\n0\n0\n0\n0\n";
}

std::vector<BenchSequence> VispBenchSequences(const std::string& visp_images,
                                              const std::string& scratch_dir) {
  std::vector<BenchSequence> sequences;
  const std::string mbt = visp_images + "/mbt";
  const std::string castle = visp_images + "/mbt-depth/Castle-simu";
  const std::string castel = visp_images + "/mbt-depth/castel";
  const std::string castle_scene = scratch_dir + "/castle_simu_scene.cao";
  if (Exists(castle + "/Models/chateau.cao")) {
    std::ofstream(castle_scene) << CastleSimuSceneCao(castle);
  }
  for (std::optional<BenchSequence> s :
       {Sequence("mbt/cube", mbt, "cube/image%04d.pgm", mbt + "/cube.cao", "cube.xml",
                 "cube.0.pos"),
        Sequence("mbt-depth/Castle-simu", castle, "Images/Image_%04d.pgm", castle_scene,
                 "Config/chateau.xml", "CameraPose/Camera_001.txt"),
        Sequence("mbt-depth/castel", castel, "castel/image_%04d.pgm", castel + "/chateau.cao",
                 "chateau.xml", "chateau.0.pos")}) {
    if (s) sequences.push_back(std::move(*s));
  }
  return sequences;
}

TrackBenchResult RunTrackBench(const BenchSequence& sequence, int repeats) {
  const std::vector<vpImage<unsigned char>> frames = LoadFrames(sequence.images);
  CameraIntrinsics camera = sequence.camera;
  camera.width = static_cast<int>(frames[0].getWidth());
  camera.height = static_cast<int>(frames[0].getHeight());
  TrackBenchResult result;
  result.name = sequence.name;
  result.frames = static_cast<int>(frames.size()) - 1;
  for (int r = 0; r < std::max(1, repeats); ++r) {
    vpMbGenericTracker visp(1, vpMbGenericTracker::EDGE_TRACKER);
    try {
      visp.loadConfigFile(sequence.visp_settings, false);
    } catch (const vpException& e) {
      throw InputError(sequence.visp_settings + ": " + e.getMessage());
    }
    LoadVispModel(sequence.model, &visp);
    EdgeTracker ours(sequence.model, camera, sequence.settings);
    SequenceTracker tracker(&ours, camera, nullptr, {});
    tracker.SetStartPose(sequence.start);
    visp.initFromPose(frames[0], ToVispPose(sequence.start));
    tracker.Process(frames[0], 0.0, std::nullopt);
    bool visp_alive = true;
    for (size_t i = 1; i < frames.size(); ++i) {
      if (visp_alive) {
        const Clock::time_point start = Clock::now();
        const double cpu = ThreadCpuMs();
        try {
          visp.track(frames[i]);
          result.visp_cpu_ms.push_back(ThreadCpuMs() - cpu);
          result.visp_ms.push_back(MillisecondsSince(start));
          if (r == 0) ++result.visp_tracked;
        } catch (const vpException&) {
          visp_alive = false;
        }
      }
      const Clock::time_point start = Clock::now();
      const double cpu = ThreadCpuMs();
      const FrameReport report = tracker.Process(frames[i], i / 30.0, std::nullopt);
      result.linetrack_cpu_ms.push_back(ThreadCpuMs() - cpu);
      result.linetrack_ms.push_back(MillisecondsSince(start));
      result.passes_ms.push_back(report.passes_ms);
      result.measure_ms.push_back(report.measure_ms);
      if (r == 0 && report.status == TrackStatus::kTracking) ++result.linetrack_tracked;
    }
  }
  // Replay: decoding from disk and the tracking step, frame after frame.
  EdgeTracker ours(sequence.model, camera, sequence.settings);
  SequenceTracker tracker(&ours, camera, nullptr, {});
  tracker.SetStartPose(sequence.start);
  const Clock::time_point start = Clock::now();
  VideoSource source(sequence.images, VideoSourceOptions());
  Frame frame;
  int decoded = 0, passes = 0;
  while (source.Grab(&frame) == FrameStatus::kOk) {
    passes += tracker.Process(frame.image, frame.timestamp_s, std::nullopt).health.passes;
    ++decoded;
  }
  const double seconds = MillisecondsSince(start) / 1000.0;
  result.replay_fps = seconds > 0.0 ? decoded / seconds : 0.0;
  result.replay_passes = decoded > 0 ? static_cast<double>(passes) / decoded : 0.0;
  return result;
}

}  // namespace linetrack::app

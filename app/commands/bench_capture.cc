// `linetrack bench capture`: capture throughput of a frame source (frames received, frames
// dropped according to the device's frame ids, mean rate), by default from Aravis' fake GigE
// Vision camera started for the occasion on 127.0.0.1.
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "app/bench/capture_bench.h"
#include "app/commands.h"
#include "models/errors.h"
#include "tracking/capture/source_factory.h"
#include "tracking/fake_gige/fake_gige_camera.h"

namespace linetrack::app {
namespace {

struct BenchCaptureOptions {
  std::string source;  // empty: the fake GigE camera
  std::string fake_serial = "LINETRACK-BENCH";
  int width = 640;
  int height = 480;
  double fps = 100.0;
  std::string pixel_format = "Mono8";
  int buffers = AravisSourceOptions().n_buffers;
  CaptureBenchOptions bench;
  bool json = false;
};

nlohmann::json ToJson(const CaptureBenchResult& r) {
  return {{"source", r.source},           {"width", r.width},
          {"height", r.height},           {"frames", r.frames},
          {"dropped", r.missed},          {"timeouts", r.timeouts},
          {"losses", r.losses},           {"incomplete", r.incomplete},
          {"underruns", r.underruns},     {"seconds", r.elapsed_s},
          {"mean_fps", r.mean_fps},       {"grab_ms_median", r.grab_ms_median},
          {"grab_ms_p95", r.grab_ms_p95}, {"reached_end", r.reached_end}};
}

int RunBenchCapture(BenchCaptureOptions opt) {
  std::string why;
  if (!opt.bench.Check(&why)) throw InputError("bench capture: " + why);
  FrameSourceOptions sources;
  sources.aravis.pixel_format = opt.pixel_format;
  sources.aravis.width = opt.width;
  sources.aravis.height = opt.height;
  sources.aravis.frame_rate = opt.fps;
  sources.aravis.n_buffers = opt.buffers;

  std::unique_ptr<FakeGigECamera> camera;
  std::string spec = opt.source;
  if (spec.empty()) {
    FakeGigECameraOptions fake;
    fake.serial = opt.fake_serial;
    camera = std::make_unique<FakeGigECamera>(fake);
    if (!camera->Start(&why)) throw std::runtime_error("fake GigE camera: " + why);
    spec = "aravis:" + fake.serial;
  }
  if (ParseSourceSpec(spec).kind == SourceKind::kVideo) {
    opt.bench.warmup_seconds = 0.0;  // files: time every frame from the first
  }
  std::unique_ptr<FrameSource> source = OpenFrameSource(spec, sources);
  const CaptureBenchResult r = RunCaptureBenchmark(source.get(), opt.bench);
  source.reset();

  if (opt.json) {
    std::cout << ToJson(r).dump(2) << std::endl;
    return kExitOk;
  }
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  out << "source        " << r.source << "\n"
      << "frame size    " << r.width << "x" << r.height << "\n"
      << "window        " << r.elapsed_s << " s" << (r.reached_end ? " (end of file)" : "") << "\n"
      << "frames        " << r.frames << "\n"
      << "dropped       " << r.missed << " (frame-id gaps)\n"
      << "mean rate     " << r.mean_fps << " frames/s\n"
      << "grab time     median " << r.grab_ms_median << " ms, 95% " << r.grab_ms_p95
      << " ms (waiting included)\n"
      << "timeouts      " << r.timeouts << ", losses " << r.losses << ", incomplete "
      << r.incomplete << ", buffer underruns " << r.underruns << "\n";
  std::cout << out.str();
  return kExitOk;
}

}  // namespace

void AddBenchCapture(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchCaptureOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "capture",
      "Capture throughput of a frame source: frames, frames dropped (frame-id gaps), mean rate. "
      "Without --source, starts Aravis' fake GigE Vision camera (arv-fake-gv-camera-0.8) on "
      "127.0.0.1 and grabs from it over the real protocol");
  cmd->add_option("--source", opt->source,
                  "aravis[:ID] | v4l2:/dev/videoN | video file | image sequence 'DIR/f_%05d.png' "
                  "(default: the fake GigE camera)");
  cmd->add_option("--seconds", opt->bench.seconds, "Length of the timed window (s)")
      ->capture_default_str();
  cmd->add_option("--warmup", opt->bench.warmup_seconds, "Frames grabbed before timing (s)")
      ->capture_default_str();
  cmd->add_option("--width", opt->width, "Aravis: image width (pixels, 0 = keep)")
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Aravis: image height (pixels, 0 = keep)")
      ->capture_default_str();
  cmd->add_option("--fps", opt->fps, "Aravis: frame rate (frames/s, 0 = keep)")
      ->capture_default_str();
  cmd->add_option("--pixel-format", opt->pixel_format, "Aravis: GenICam pixel format")
      ->capture_default_str();
  cmd->add_option("--buffers", opt->buffers, "Aravis: stream buffers")->capture_default_str();
  cmd->add_option("--fake-serial", opt->fake_serial, "Serial number of the fake camera")
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, action, cmd] {
    RefuseUnless(*cmd, opt->source.empty() || opt->source.rfind("aravis", 0) == 0,
                 {"--width", "--height", "--fps", "--pixel-format", "--buffers"},
                 "applies to Aravis cameras (--source aravis[:ID] or the fake camera)");
    RefuseUnless(*cmd, opt->source.empty(), {"--fake-serial"},
                 "applies to the fake camera (without --source)");
    *action = [opt] { return RunBenchCapture(*opt); };
  });
}

}  // namespace linetrack::app

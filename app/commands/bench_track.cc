// `linetrack bench track`: the per-frame cost of linetrack's tracking step (undistortion, tracking
// passes, health) beside ViSP's bare vpMbGenericTracker::track() on the same frames in the same
// run, and the replay throughput (decoding + tracking, no encoding), on visp-images-data.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/bench/track_bench.h"
#include "app/commands.h"
#include "models/errors.h"
#include "models/statistics.h"

namespace linetrack::app {
namespace {

struct BenchTrackOptions {
  std::string visp_images;
  int repeats = 3;
  int passes = 0;                 // 0: the settings' own
  double pass_step_factor = 0.0;  // 0: the settings' own
  bool no_refinement = false;
  int first_passes_iterations = -1;  // < 0: the settings' own
  bool json = false;
};

std::string DefaultVispImages() {
  const char* env = std::getenv("VISP_INPUT_IMAGE_PATH");
  return std::string(env ? env : "/usr/share/visp-images-data") + "/ViSP-images";
}

int RunBenchTrack(const BenchTrackOptions& opt) {
  if (opt.repeats < 1 || opt.repeats > 100) throw InputError("--repeats: must be in [1, 100]");
  const std::string images = opt.visp_images.empty() ? DefaultVispImages() : opt.visp_images;
  if (!std::filesystem::is_directory(images)) {
    throw InputError(images + ": no ViSP-images folder (install visp-images-data)");
  }
  const std::filesystem::path scratch = std::filesystem::temp_directory_path() /
                                        ("linetrack_bench_track_" + std::to_string(getpid()));
  std::filesystem::create_directories(scratch);
  std::vector<BenchSequence> sequences = VispBenchSequences(images, scratch.string());
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  std::cout << std::fixed << std::setprecision(2);
  if (!opt.json) {
    std::cout << "sequence               frames  ViSP track() ms         linetrack step ms       "
                 "ratio  replay  passes  tracked\n"
                 "                               median  p90    cpu     median  p90    cpu      "
                 "(cpu)   fps    /frame  ViSP/linetrack\n";
  }
  for (BenchSequence& s : sequences) {
    if (opt.passes > 0) s.settings.passes = opt.passes;
    if (opt.pass_step_factor > 0.0) s.settings.pass_step_factor = opt.pass_step_factor;
    if (opt.no_refinement) s.settings.refine_subpixel = false;
    if (opt.first_passes_iterations >= 0) {
      s.settings.first_passes_max_iterations = opt.first_passes_iterations;
    }
    const TrackBenchResult r = RunTrackBench(s, opt.repeats);
    const double visp_median = QuantileNearestRank(r.visp_ms, 0.5);
    const double ours_median = QuantileNearestRank(r.linetrack_ms, 0.5);
    const double visp_cpu = QuantileNearestRank(r.visp_cpu_ms, 0.5);
    const double ours_cpu = QuantileNearestRank(r.linetrack_cpu_ms, 0.5);
    const double ratio = visp_cpu > 0.0 ? ours_cpu / visp_cpu : 0.0;
    rows.push_back({{"sequence", r.name},
                    {"frames", r.frames},
                    {"visp_ms_median", visp_median},
                    {"visp_ms_p90", QuantileNearestRank(r.visp_ms, 0.9)},
                    {"visp_cpu_ms_median", visp_cpu},
                    {"linetrack_ms_median", ours_median},
                    {"linetrack_ms_p90", QuantileNearestRank(r.linetrack_ms, 0.9)},
                    {"linetrack_cpu_ms_median", ours_cpu},
                    {"cpu_ratio_of_medians", ratio},
                    {"replay_fps", r.replay_fps},
                    {"passes_per_frame", r.replay_passes},
                    {"visp_tracked", r.visp_tracked},
                    {"linetrack_tracked", r.linetrack_tracked},
                    {"passes_ms_median", QuantileNearestRank(r.passes_ms, 0.5)},
                    {"measure_ms_median", QuantileNearestRank(r.measure_ms, 0.5)}});
    if (!opt.json) {
      std::cout << std::left << std::setw(23) << r.name << std::right << std::setw(6) << r.frames
                << std::setw(8) << visp_median << std::setw(7)
                << QuantileNearestRank(r.visp_ms, 0.9) << std::setw(7) << visp_cpu << std::setw(9)
                << ours_median << std::setw(7) << QuantileNearestRank(r.linetrack_ms, 0.9)
                << std::setw(7) << ours_cpu << std::setw(8) << ratio << std::setw(8)
                << std::setprecision(0) << r.replay_fps << std::setprecision(2) << std::setw(8)
                << r.replay_passes << "  " << r.visp_tracked << "/" << r.linetrack_tracked << "\n"
                << "    linetrack stages, wall medians: ViSP passes "
                << QuantileNearestRank(r.passes_ms, 0.5)
                << " ms, moving-edge states and refinement "
                << QuantileNearestRank(r.measure_ms, 0.5) << " ms\n";
    }
  }
  std::error_code ec;
  std::filesystem::remove_all(scratch, ec);
  if (opt.json) std::cout << rows.dump(2) << std::endl;
  if (sequences.empty()) throw InputError(images + ": none of the bench sequences is there");
  return kExitOk;
}

}  // namespace

void AddBenchTrack(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchTrackOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "track",
      "Per-frame cost of linetrack's tracking step beside ViSP's bare track() on the same frames "
      "(mbt/cube, Castle-simu, castel), and replay throughput");
  cmd->add_option("--visp-images", opt->visp_images,
                  "ViSP-images folder (default: $VISP_INPUT_IMAGE_PATH/ViSP-images or the Debian "
                  "package's)");
  cmd->add_option("--repeats", opt->repeats, "Runs over each sequence (times pooled)")
      ->capture_default_str();
  cmd->add_option("--passes", opt->passes, "Override the minimum tracking passes per frame");
  cmd->add_option("--pass-step-factor", opt->pass_step_factor,
                  "Override the sample step factor of each pass");
  cmd->add_option("--first-passes-iterations", opt->first_passes_iterations,
                  "Override the ViSP iterations of every pass but the last (0: all the same)");
  cmd->add_flag("--no-refinement", opt->no_refinement, "Skip the sub-pixel refinement");
  cmd->add_flag("--json", opt->json, "Print the table as JSON");
  cmd->callback([opt, action] { *action = [opt] { return RunBenchTrack(*opt); }; });
}

}  // namespace linetrack::app

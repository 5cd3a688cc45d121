// `linetrack bench drive`: long rendered drives (people crossing, blackouts, exposure changes,
// motion blur, a panning head, drifting odometry) through the bundled buildings, each rendered
// once into a work folder by `render` and replayed by `replay` (the commands themselves, run in
// this process), judged against the drives' truth: markdown tables on stdout.
//   linetrack bench drive [DRIVE.json ...] [--drives DIR] [--work DIR] [--frames N]
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/commands.h"
#include "app/drive_metrics.h"
#include "models/errors.h"
#include "models/render/frame_truth.h"
#include "models/silence_stdout.h"
#include "models/trajectory_io.h"

namespace linetrack::app {
namespace {

namespace fs = std::filesystem;

struct BenchDriveOptions {
  std::vector<std::string> drive_files;
  std::string drives_dir = "models/drives";
  std::string work = "out/bench-drive";
  int frames = 0;  // 0: as the drive says
  bool rerender = false;
  bool json = false;
  DriveMetricsOptions metrics;
};

// Flags of `render` whose values are files, resolved relative to the drive file.
const char* const kFileFlags[] = {"model", "camera", "nav", "path", "trajectory", "settings"};

// A drive: its name and the `render` (and extra `replay`) flags of its file.
struct DriveSpec {
  std::string name, file;
  std::vector<std::string> render_args;  // without --out and --frames
  std::vector<std::string> replay_args;  // extra flags
  std::string model;
  int frames = 0;
};

// "--key value" pairs of a JSON object of flags (true: the flag alone; an array of strings: the
// flag repeated with each).
std::vector<std::string> FlagArgs(const nlohmann::json& flags, const fs::path& base,
                                  const std::string& where) {
  if (!flags.is_object()) throw InputError(where + ": expected an object of flags");
  std::vector<std::string> args;
  for (const auto& [key, value] : flags.items()) {
    if (value.is_array()) {
      for (const nlohmann::json& item : value) {
        if (!item.is_string()) throw InputError(where + ": flag '" + key + "': strings expected");
        args.insert(args.end(), {"--" + key, item.get<std::string>()});
      }
      continue;
    }
    args.push_back("--" + key);
    if (value.is_boolean()) {
      if (!value.get<bool>()) args.pop_back();
      continue;
    }
    std::string text;
    if (value.is_string()) {
      text = value.get<std::string>();
    } else if (value.is_number()) {
      text = value.dump();
    } else {
      throw InputError(where + ": flag '" + key + "' must be a string, number or boolean");
    }
    const bool file =
        std::find(std::begin(kFileFlags), std::end(kFileFlags), key) != std::end(kFileFlags);
    if (file && text != "hall-loop") text = (base / text).lexically_normal().string();
    args.push_back(text);
  }
  return args;
}

using AddCommand = std::function<void(CLI::App&, CommandAction*)>;

// Parses the flags of one of linetrack's commands: its job, or InputError naming `source` (the
// drive file that gave the flags).
CommandAction ParseCommand(const AddCommand& add, std::vector<std::string> args,
                           const std::string& source) {
  CLI::App cli;
  CommandAction action;
  add(cli, &action);
  std::reverse(args.begin(), args.end());
  try {
    cli.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError(source + ": " + e.what());
  }
  if (!action) throw InputError(source + ": no command to run");
  return action;
}

// Runs one of linetrack's commands in this process, its stdout discarded.
int RunCommand(const AddCommand& add, const std::vector<std::string>& args,
               const std::string& source) {
  const CommandAction action = ParseCommand(add, args, source);
  ScopedStdoutSilencer quiet;
  return action();
}

DriveSpec ReadDrive(const std::string& file) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ReadTextFile(file, "drive"));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file + ": not a drive file (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("name") || !j["name"].is_string() || !j.contains("render")) {
    throw InputError(file + ": a drive file needs \"name\" and \"render\"");
  }
  DriveSpec d;
  d.file = file;
  d.name = j["name"].get<std::string>();
  const fs::path base = fs::path(file).parent_path();
  nlohmann::json render = j["render"];
  if (!render.is_object() || !render.contains("model") || !render.contains("camera")) {
    throw InputError(file + ": \"render\" needs at least \"model\" and \"camera\"");
  }
  if (render.contains("out")) throw InputError(file + ": \"render\" must not give \"out\"");
  if (render.contains("frames")) {
    if (!render["frames"].is_number_integer()) throw InputError(file + ": frames: an integer");
    d.frames = render["frames"].get<int>();
    render.erase("frames");
  }
  d.render_args = FlagArgs(render, base, file + ": render");
  d.model = (base / render["model"].get<std::string>()).lexically_normal().string();
  if (j.contains("replay")) d.replay_args = FlagArgs(j["replay"], base, file + ": replay");
  // The flags are checked before anything is rendered.
  std::vector<std::string> render_args = {"render", "--out", "unused"};
  render_args.insert(render_args.end(), d.render_args.begin(), d.render_args.end());
  ParseCommand(AddRender, render_args, file);
  std::vector<std::string> replay_args = {"replay",   "--input", "x",     "--model", "x",
                                          "--camera", "x",       "--out", "x"};
  replay_args.insert(replay_args.end(), d.replay_args.begin(), d.replay_args.end());
  ParseCommand(AddReplay, replay_args, file);
  return d;
}

std::vector<std::string> DriveFiles(const BenchDriveOptions& opt) {
  if (!opt.drive_files.empty()) return opt.drive_files;
  std::vector<std::string> files;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(opt.drives_dir, ec)) {
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  }
  if (ec) throw InputError(opt.drives_dir + ": cannot list the drive folder");
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(opt.drives_dir + ": no drive files (*.json)");
  return files;
}

// The key of a rendered drive: the render flags and the contents of the files they name.
std::string RenderKey(const std::vector<std::string>& args) {
  std::string key = LINETRACK_VERSION;
  for (size_t i = 0; i < args.size(); ++i) {
    key += "\n" + args[i];
    std::error_code ec;
    if (i > 0 && args[i - 1].rfind("--", 0) == 0 && fs::is_regular_file(args[i], ec)) {
      key += " #" + std::to_string(std::hash<std::string>()(ReadTextFile(args[i], "input")));
    }
  }
  return key + "\n";
}

// Renders the drive into DIR/frames unless the same render is there already; `frames` > 0
// replaces the drive's own count.
void RenderDrive(const DriveSpec& d, int frames, bool rerender, const fs::path& dir) {
  std::vector<std::string> args = {"render"};
  args.insert(args.end(), d.render_args.begin(), d.render_args.end());
  if (frames <= 0) frames = d.frames;
  if (frames > 0) args.insert(args.end(), {"--frames", std::to_string(frames)});
  const std::string key = RenderKey(args);
  const fs::path frames_dir = dir / "frames", key_file = dir / "render.key";
  std::error_code ec;
  if (!rerender && fs::exists(key_file, ec) &&
      ReadTextFile(key_file.string(), "render key") == key &&
      fs::exists(frames_dir / "frame_truth.csv", ec)) {
    spdlog::info("{}: rendered frames found in {}", d.name, frames_dir.string());
    return;
  }
  fs::remove(key_file, ec);
  fs::remove_all(frames_dir, ec);
  spdlog::info("{}: rendering into {}", d.name, frames_dir.string());
  args.insert(args.end(), {"--out", frames_dir.string()});
  if (RunCommand(AddRender, args, d.file) != kExitOk) {
    throw InputError(d.file + ": the drive could not be rendered");
  }
  WriteFileAtomically(key_file.string(), key);
}

DriveReport ReplayDrive(const DriveSpec& d, const fs::path& dir, const BenchDriveOptions& opt,
                        std::vector<FrameTruth>* truth, std::vector<ReplayedFrame>* replayed) {
  const fs::path frames_dir = dir / "frames", out = dir / "replay";
  std::error_code ec;
  fs::remove_all(out, ec);
  std::vector<std::string> args = {"replay",
                                   "--input",
                                   (frames_dir / "frame_%05d.png").string(),
                                   "--model",
                                   d.model,
                                   "--camera",
                                   (frames_dir / "camera.xml").string(),
                                   "--prior-file",
                                   (frames_dir / "priors.csv").string(),
                                   "--ground-truth",
                                   (frames_dir / "groundtruth.txt").string(),
                                   "--out",
                                   out.string(),
                                   "--no-overlay"};
  args.insert(args.end(), d.replay_args.begin(), d.replay_args.end());
  spdlog::info("{}: replaying into {}", d.name, out.string());
  RunCommand(AddReplay, args, d.file);  // exit 1 (no pose at all) still has figures
  *truth = ReadFrameTruth((frames_dir / "frame_truth.csv").string());
  *replayed = ParseReplayFrames(ReadTextFile((out / "frames.csv").string(), "replay frames"),
                                (out / "frames.csv").string());
  const nlohmann::json summary =
      nlohmann::json::parse(ReadTextFile((out / "summary.json").string(), "replay summary"));
  const nlohmann::json sequence =
      nlohmann::json::parse(ReadTextFile((frames_dir / "sequence.json").string(), "sequence"));
  DriveReport report;
  report.name = d.name;
  report.metrics =
      ComputeDriveMetrics(*truth, *replayed, summary.value("throughput_fps", 0.0), opt.metrics);
  if (summary.contains("integrity")) AddIntegrityFigures(summary["integrity"], &report.metrics);
  std::vector<long> kidnaps;
  if (sequence.contains("kidnaps")) {
    for (const nlohmann::json& k : sequence["kidnaps"])
      kidnaps.push_back(k.value("frame", 0L));
  }
  AddKidnapRecoveries(*truth, *replayed, kidnaps, opt.metrics, &report.metrics);
  report.drift_percent = sequence["odometry_drift"].value("max_percent", 0.0);
  return report;
}

int RunBenchDrive(const BenchDriveOptions& opt) {
  std::string why;
  if (!opt.metrics.Check(&why)) throw InputError("bench drive: " + why);
  if (opt.frames < 0) throw InputError("--frames: must be >= 0");
  std::vector<DriveSpec> drives;
  for (const std::string& file : DriveFiles(opt))
    drives.push_back(ReadDrive(file));
  EnsureDirectory(opt.work);
  std::vector<DriveReport> reports;
  std::string details;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const DriveSpec& d : drives) {
    const fs::path dir = fs::path(opt.work) / d.name;
    EnsureDirectory(dir.string());
    RenderDrive(d, opt.frames, opt.rerender, dir);
    std::vector<FrameTruth> truth;
    std::vector<ReplayedFrame> replayed;
    reports.push_back(ReplayDrive(d, dir, opt, &truth, &replayed));
    const DriveMetrics& m = reports.back().metrics;
    details += "\n### " + d.name + ": worst frames\n\n" + FormatWorstFrames(m, truth, replayed);
    rows.push_back({{"drive", d.name},
                    {"frames", m.frames},
                    {"observable", m.observable},
                    {"availability", m.Availability()},
                    {"tracking_availability", m.TrackingAvailability()},
                    {"observable_tracking_coasted", m.observable_tracking_coasted},
                    {"poses", m.poses},
                    {"beyond_near", m.beyond_near},
                    {"beyond_far", m.beyond_far},
                    {"poses_unobservable", m.poses_unobservable},
                    {"ate_m", m.ate_m},
                    {"worst_m", m.worst_m},
                    {"worst_deg", m.worst_deg},
                    {"tracking_fps", m.tracking_fps},
                    {"overall_fps", m.overall_fps},
                    {"odometry_drift_percent", reports.back().drift_percent},
                    {"tracking_beyond_near", m.tracking_beyond_near},
                    {"integrity_failures", m.integrity_failures ? *m.integrity_failures : -1},
                    {"nees_shares", m.nees_shares}});
  }
  double load[1] = {0.0};
  const bool has_load = getloadavg(load, 1) == 1;
  if (opt.json) {
    std::cout << rows.dump(2) << std::endl;
  } else {
    std::cout << FormatDriveTable(reports, opt.metrics);
    if (has_load) {
      std::cout << "\nReplay fps are wall-clock (load average " << std::fixed
                << std::setprecision(1) << load[0] << " when the last replay ended).\n";
    }
    std::cout << details;
  }
  return kExitOk;
}

}  // namespace

void AddBenchDrive(CLI::App& cli, CommandAction* action) {
  auto opt = std::make_shared<BenchDriveOptions>();
  CLI::App* cmd = BenchGroup(cli)->add_subcommand(
      "drive",
      "Long rendered drives (people, blackouts, exposure changes, motion blur, a panning head, "
      "drifting odometry) replayed and judged against their truth: markdown tables");
  cmd->add_option("drives", opt->drive_files, "Drive files (default: every *.json of --drives)");
  cmd->add_option("--drives", opt->drives_dir, "Folder of drive files")->capture_default_str();
  cmd->add_option("--work", opt->work, "Work folder: rendered drives (kept) and replays")
      ->capture_default_str();
  cmd->add_option("--frames", opt->frames, "Render and replay only the first N frames");
  cmd->add_flag("--rerender", opt->rerender, "Render again even when the frames are there");
  cmd->add_option("--worst", opt->metrics.worst, "Frames in each worst-frames list")
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print the figures as JSON");
  cmd->callback([opt, action] { *action = [opt] { return RunBenchDrive(*opt); }; });
}

}  // namespace linetrack::app

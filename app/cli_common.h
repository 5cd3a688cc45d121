// Shared helpers for the subcommands: option parsing into the project's types, output files that
// appear only when complete, and the exit codes every command uses.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "models/camera.h"
#include "models/robot_pose.h"

namespace linetrack::app {

// Exit codes of every command.
constexpr int kExitOk = 0;
constexpr int kExitJobFailed = 1;  // the job ran but failed (e.g. no pose found)
constexpr int kExitBadInput = 2;   // bad usage or bad input (one line on stderr)

// What a chosen subcommand runs after parsing; returns the exit code.
using CommandAction = std::function<int()>;

// Parses `count` comma-separated finite numbers ("1.5,2,-3"; no empty or trailing field); `form`
// names them in errors (e.g. "X,Y,Z"). Throws InputError naming `flag` when malformed.
std::vector<double> ParseNumberList(const std::string& text, size_t count, const std::string& flag,
                                    const std::string& form);

// Parses "X,Y,HEADING_DEG" (metres, metres, degrees) into a Pose3Dof with heading in radians.
// Throws InputError naming `flag` when malformed or not finite.
Pose3Dof ParsePrior(const std::string& text, const std::string& flag);

// ParseNumberList with errors saying "`count` comma-separated numbers".
std::vector<double> ParseNumbers(const std::string& text, int count, const std::string& flag);

// Throws InputError unless `value` is finite and within [lo, hi] (names `flag`).
void CheckRange(double value, double lo, double hi, const std::string& flag);

// Throws InputError (naming `what`, e.g. "x.csv: --prior-file") unless some of `times` (seconds,
// already shifted by any --time-offset) fall within [first - tolerance, last + tolerance], the
// frames' times: a file stamped in another time base (epoch seconds against frames from 0).
void CheckTimesOverlap(const std::vector<double>& times, double first, double last,
                       double tolerance, const std::string& what);

// Throws InputError unless `metres` is a camera height above the floor: finite, positive and at
// most 100 m (names `flag`).
void CheckHeight(double metres, const std::string& flag);

// Refuses the flags that cannot apply: throws CLI::ValidationError "FLAG: WHY" for the first of
// `flags` given on `cmd` when `applies` is false, so that no flag is silently ignored.
void RefuseUnless(const CLI::App& cmd, bool applies, const std::vector<std::string>& flags,
                  const std::string& why);

// Writes `content` to `path` through a temporary file renamed into place, so that a reader never
// sees a partial file. Throws InputError when the file cannot be written.
void WriteFileAtomically(const std::string& path, const std::string& content);

// The `bench` command group shared by the benchmarks (created by the first caller).
CLI::App* BenchGroup(CLI::App& cli);

// While an object lives, SIGINT and SIGTERM are recorded instead of ending the process, so that a
// long run (replay, live) can stop cleanly; the previous handlers come back when it dies.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The signal received since construction (SIGINT or SIGTERM), 0 for none.
  static int Received();
  // "SIGINT" or "SIGTERM" (empty for none).
  static std::string ReceivedName();

 private:
  struct Saved;
  std::unique_ptr<Saved> saved_;
};

// The camera of `path`: a ViSP camera XML, an OpenCV calibration file or a ROS camera_info YAML
// (ReadCamera, models/camera_file.h). Says on stderr how closely ViSP's one-term distortion
// stands for the Brown-Conrady distortion of an OpenCV or ROS file. Throws InputError.
CameraIntrinsics LoadCamera(const std::string& path, const std::string& name = "");

// Creates `dir` (and parents) when missing; throws InputError when it cannot.
void EnsureDirectory(const std::string& dir);

}  // namespace linetrack::app

#include "app/bench/capture_bench.h"

#include <algorithm>
#include <chrono>
#include <vector>

#include "models/statistics.h"

namespace linetrack::app {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

bool CaptureBenchOptions::Check(std::string* why) const {
  if (!(seconds > 0.0 && seconds <= 3600.0)) {
    *why = "benchmark duration must be in (0, 3600] seconds";
    return false;
  }
  if (!(warmup_seconds >= 0.0 && warmup_seconds <= 60.0)) {
    *why = "warm-up must be in [0, 60] seconds";
    return false;
  }
  return true;
}

CaptureBenchResult RunCaptureBenchmark(FrameSource* source, const CaptureBenchOptions& options) {
  CaptureBenchResult result;
  result.source = source->Describe();
  Frame frame;
  const auto warmup_end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(options.warmup_seconds));
  while (Clock::now() < warmup_end) {
    const FrameStatus status = source->Grab(&frame);
    if (status == FrameStatus::kEndOfStream) break;
  }
  const SourceStats before = source->Stats();
  std::vector<double> grab_ms;
  const auto start = Clock::now();
  const auto end = start + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(options.seconds));
  while (Clock::now() < end) {
    const auto t0 = Clock::now();
    const FrameStatus status = source->Grab(&frame);
    if (status == FrameStatus::kEndOfStream) {
      result.reached_end = true;
      break;
    }
    if (status == FrameStatus::kOk) {
      grab_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      result.width = static_cast<int>(frame.image.getWidth());
      result.height = static_cast<int>(frame.image.getHeight());
    }
  }
  result.elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  const SourceStats after = source->Stats();
  result.frames = after.delivered - before.delivered;
  result.missed = after.missed - before.missed;
  result.timeouts = after.timeouts - before.timeouts;
  result.losses = after.losses - before.losses;
  result.incomplete = after.incomplete - before.incomplete;
  result.underruns = after.underruns - before.underruns;
  result.mean_fps =
      result.elapsed_s > 0.0 ? static_cast<double>(result.frames) / result.elapsed_s : 0.0;
  result.grab_ms_median = QuantileLowerRank(grab_ms, 0.5);
  result.grab_ms_p95 = QuantileLowerRank(grab_ms, 0.95);
  return result;
}

}  // namespace linetrack::app

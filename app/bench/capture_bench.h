// Capture throughput of any frame source: frames received, frames missed according to the
// device's frame ids, mean rate. The body of `linetrack bench capture`.
#pragma once

#include <cstdint>
#include <string>

#include "tracking/capture/frame_source.h"

namespace linetrack::app {

struct CaptureBenchOptions {
  double seconds = 5.0;         // how long to grab (files stop earlier at their end)
  double warmup_seconds = 0.5;  // frames grabbed before the clock starts (not counted)

  bool Check(std::string* why) const;
};

struct CaptureBenchResult {
  std::string source;         // the source's Describe()
  int width = 0, height = 0;  // size of the last frame
  std::int64_t frames = 0;    // frames received in the timed window
  std::int64_t missed = 0;    // frame-id gaps in the timed window (dropped frames)
  std::int64_t timeouts = 0, losses = 0, incomplete = 0, underruns = 0;
  double elapsed_s = 0.0;                          // timed window
  double mean_fps = 0.0;                           // frames / elapsed_s
  double grab_ms_median = 0.0, grab_ms_p95 = 0.0;  // time spent in Grab() per delivered frame
  bool reached_end = false;                        // a file source ran out of frames
};

// Grabs from `source` for options.seconds (after the warm-up) and measures.
CaptureBenchResult RunCaptureBenchmark(FrameSource* source, const CaptureBenchOptions& options);

}  // namespace linetrack::app

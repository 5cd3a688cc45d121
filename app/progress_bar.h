// A progress bar on stderr for long runs over frames (`replay`).
#pragma once

#include <chrono>

namespace linetrack::app {

// Prints "[###   ] done/total frames, F frames/s, N with a pose" on stderr when it is a terminal,
// at most ten times a second (total <= 0: no bar, no total).
class Progress {
 public:
  Progress(long total, bool enabled);
  void Update(long done, int tracked, bool force = false);

 private:
  using Clock = std::chrono::steady_clock;
  long total_;
  bool enabled_;
  Clock::time_point start_ = Clock::now(), last_;
};

}  // namespace linetrack::app

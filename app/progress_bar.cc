#include "app/progress_bar.h"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace linetrack::app {

Progress::Progress(long total, bool enabled)
    : total_(total), enabled_(enabled && isatty(STDERR_FILENO)) {}

void Progress::Update(long done, int tracked, bool force) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  const double seconds = std::chrono::duration<double>(now - start_).count();
  std::string bar;
  if (total_ > 0) {
    const int filled = static_cast<int>(30.0 * done / total_);
    bar = "[" + std::string(filled, '#') + std::string(30 - filled, ' ') + "] ";
  }
  std::fprintf(stderr, "\r%s%ld%s frames, %.0f frames/s, %d with a pose   ", bar.c_str(), done,
               total_ > 0 ? ("/" + std::to_string(total_)).c_str() : "",
               seconds > 0 ? done / seconds : 0.0, tracked);
  if (force) std::fprintf(stderr, "\n");
}

}  // namespace linetrack::app

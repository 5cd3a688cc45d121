// ViSP prints progress on std::cout in places (vpXmlParserCamera's "Found camera with name",
// vpMbGenericTracker::loadModel's model summary); stdout belongs to linetrack's own output.
#pragma once

#include <iostream>
#include <sstream>

namespace linetrack {

// Discards what is written to std::cout while it lives (not thread-safe: std::cout is global).
class ScopedStdoutSilencer {
 public:
  ScopedStdoutSilencer() : saved_(std::cout.rdbuf(sink_.rdbuf())) {}
  ~ScopedStdoutSilencer() { std::cout.rdbuf(saved_); }
  ScopedStdoutSilencer(const ScopedStdoutSilencer&) = delete;
  ScopedStdoutSilencer& operator=(const ScopedStdoutSilencer&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* saved_;
};

}  // namespace linetrack

// A serial line (or pseudo-terminal) in raw mode, read line by line with deadlines. Lines end
// with CR or LF; empty lines are skipped. No call blocks past its deadline.
#pragma once

#include <chrono>
#include <deque>
#include <string>

namespace linetrack {

class SerialLine {
 public:
  using Clock = std::chrono::steady_clock;
  enum class ReadStatus { kLine, kTimeout, kError };

  SerialLine() = default;
  ~SerialLine();
  SerialLine(const SerialLine&) = delete;
  SerialLine& operator=(const SerialLine&) = delete;

  // Opens `path` raw 8N1 without flow control at `baud` (one of the standard rates; pseudo-
  // terminals ignore it) and flushes stale input. False with *why set (naming the path).
  bool Open(const std::string& path, int baud, std::string* why);
  bool is_open() const { return fd_ >= 0; }
  void Close();

  // Writes all of `text` before `deadline`.
  bool Write(const std::string& text, Clock::time_point deadline, std::string* why);

  // The next non-empty line (without terminator), waiting until `deadline`.
  ReadStatus ReadLine(Clock::time_point deadline, std::string* line, std::string* why);

  // Reads whatever has arrived without waiting; complete lines are queued for ReadLine.
  void Poll();

  // Complete lines received and not read yet, and the partial line after them.
  std::deque<std::string>& pending_lines() { return lines_; }
  std::string& partial() { return partial_; }

 private:
  // Reads available bytes into the buffers; waits up to `timeout_ms` (0: no wait). False on a
  // read error or hang-up.
  bool Fill(int timeout_ms, std::string* why);

  int fd_ = -1;
  std::string path_;
  std::deque<std::string> lines_;
  std::string partial_;
};

}  // namespace linetrack

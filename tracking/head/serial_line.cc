#include "tracking/head/serial_line.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace linetrack {
namespace {

bool BaudConstant(int baud, speed_t* speed) {
  static const struct {
    int baud;
    speed_t constant;
  } kRates[] = {{1200, B1200},     {2400, B2400},    {4800, B4800},   {9600, B9600},
                {19200, B19200},   {38400, B38400},  {57600, B57600}, {115200, B115200},
                {230400, B230400}, {460800, B460800}};
  for (const auto& r : kRates) {
    if (r.baud == baud) {
      *speed = r.constant;
      return true;
    }
  }
  return false;
}

int MillisecondsUntil(SerialLine::Clock::time_point deadline) {
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SerialLine::Clock::now())
          .count();
  return ms < 0 ? 0 : static_cast<int>(ms);
}

}  // namespace

SerialLine::~SerialLine() {
  Close();
}

void SerialLine::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  lines_.clear();
  partial_.clear();
}

bool SerialLine::Open(const std::string& path, int baud, std::string* why) {
  Close();
  speed_t speed = 0;
  if (!BaudConstant(baud, &speed)) {
    *why = path + ": unsupported baud rate " + std::to_string(baud);
    return false;
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *why = path + ": " + std::strerror(errno) +
           (errno == EACCES ? " (add the user to the dialout group, or a udev rule)" : "");
    return false;
  }
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    *why = path + ": not a serial line (" + std::strerror(errno) + ")";
    ::close(fd);
    return false;
  }
  cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~(CSTOPB | CRTSCTS | PARENB);
  tio.c_cflag = (tio.c_cflag & ~CSIZE) | CS8;
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  cfsetispeed(&tio, speed);
  cfsetospeed(&tio, speed);
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    *why = path + ": cannot configure the line (" + std::strerror(errno) + ")";
    ::close(fd);
    return false;
  }
  tcflush(fd, TCIOFLUSH);
  fd_ = fd;
  path_ = path;
  return true;
}

bool SerialLine::Write(const std::string& text, Clock::time_point deadline, std::string* why) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      *why = path_ + ": write failed (" + std::strerror(errno) + ")";
      return false;
    }
    const int wait_ms = MillisecondsUntil(deadline);
    if (wait_ms == 0) {
      *why = path_ + ": write timed out";
      return false;
    }
    pollfd p{fd_, POLLOUT, 0};
    ::poll(&p, 1, wait_ms);
  }
  return true;
}

bool SerialLine::Fill(int timeout_ms, std::string* why) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready < 0) {
    if (errno == EINTR) return true;
    *why = path_ + ": poll failed (" + std::strerror(errno) + ")";
    return false;
  }
  if (ready == 0) return true;
  if ((p.revents & (POLLERR | POLLNVAL)) != 0) {
    *why = path_ + ": line error";
    return false;
  }
  char buffer[512];
  for (;;) {
    const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n > 0) {
      for (ssize_t i = 0; i < n; ++i) {
        const char c = buffer[i];
        if (c == '\r' || c == '\n') {
          if (!partial_.empty()) lines_.push_back(partial_);
          partial_.clear();
        } else {
          partial_.push_back(c);
        }
      }
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return true;
    if (n == 0 && (p.revents & POLLHUP) == 0) return true;
    *why = path_ +
           (n == 0 ? ": hang-up" : std::string(": read failed (") + std::strerror(errno) + ")");
    return false;
  }
}

void SerialLine::Poll() {
  std::string ignored;
  if (fd_ >= 0) Fill(0, &ignored);
}

SerialLine::ReadStatus SerialLine::ReadLine(Clock::time_point deadline, std::string* line,
                                            std::string* why) {
  for (;;) {
    if (!lines_.empty()) {
      *line = lines_.front();
      lines_.pop_front();
      return ReadStatus::kLine;
    }
    const int wait_ms = MillisecondsUntil(deadline);
    if (!Fill(wait_ms, why)) return ReadStatus::kError;
    if (lines_.empty() && Clock::now() >= deadline) return ReadStatus::kTimeout;
  }
}

}  // namespace linetrack

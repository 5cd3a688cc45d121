#include "tests/support/ptu_emulator.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace linetrack {
namespace {

bool ParseInteger(const std::string& text, long* value) {
  if (text.empty()) return false;
  std::size_t i = (text[0] == '-' || text[0] == '+') ? 1 : 0;
  if (i == text.size() || text.size() - i > 9) return false;
  for (std::size_t k = i; k < text.size(); ++k) {
    if (!std::isdigit(static_cast<unsigned char>(text[k]))) return false;
  }
  *value = std::strtol(text.c_str(), nullptr, 10);
  return true;
}

std::string Upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

}  // namespace

PtuEmulator::PtuEmulator(const PtuEmulatorOptions& options) : options_(options) {
  pan_ = {'P',
          "Pan",
          0.0,
          0.0,
          static_cast<double>(options.initial_speed),
          options.pan_min,
          options.pan_max,
          options.pan_max_speed,
          options.pan_resolution_arcsec};
  tilt_ = {'T',
           "Tilt",
           0.0,
           0.0,
           static_cast<double>(options.initial_speed),
           options.tilt_min,
           options.tilt_max,
           options.tilt_max_speed,
           options.tilt_resolution_arcsec};
}

std::unique_ptr<PtuEmulator> PtuEmulator::Start(const PtuEmulatorOptions& options,
                                                std::string* why) {
  std::unique_ptr<PtuEmulator> emulator(new PtuEmulator(options));
  const int master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
    *why = std::string("cannot create a pseudo-terminal: ") + std::strerror(errno);
    if (master >= 0) ::close(master);
    return nullptr;
  }
  char name[128];
  if (ptsname_r(master, name, sizeof(name)) != 0) {
    *why = std::string("ptsname: ") + std::strerror(errno);
    ::close(master);
    return nullptr;
  }
  const int slave = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave < 0) {
    *why = std::string(name) + ": " + std::strerror(errno);
    ::close(master);
    return nullptr;
  }
  termios tio{};
  tcgetattr(slave, &tio);
  cfmakeraw(&tio);  // no echo or line editing by the terminal itself: the emulator does it
  tcsetattr(slave, TCSANOW, &tio);
  fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
  emulator->master_ = master;
  emulator->slave_ = slave;
  emulator->device_path_ = name;
  emulator->thread_ = std::thread([raw = emulator.get()] { raw->Run(); });
  return emulator;
}

PtuEmulator::~PtuEmulator() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (slave_ >= 0) ::close(slave_);
  if (master_ >= 0) ::close(master_);
}

void PtuEmulator::Run() {
  std::string token;
  char buffer[256];
  while (!stop_) {
    pollfd p{master_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    const ssize_t n = ::read(master_, buffer, sizeof(buffer));
    for (ssize_t i = 0; i < n; ++i) {
      const char c = buffer[i];
      if (c == ' ' || c == '\r' || c == '\n') {
        if (!token.empty()) Handle(token, c);
        token.clear();
      } else {
        token.push_back(c);
      }
    }
  }
}

void PtuEmulator::Send(const std::string& bytes) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  std::size_t done = 0;
  for (int spins = 0; done < bytes.size() && spins < 1000; ++spins) {
    const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else {
      pollfd p{master_, POLLOUT, 0};
      ::poll(&p, 1, 10);
    }
  }
}

void PtuEmulator::Handle(const std::string& token, char delimiter) {
  std::string out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string command = Upper(token);
    commands_.push_back(command);
    if (options_.seconds_per_command > 0.0) AdvanceLocked(options_.seconds_per_command);
    if (!responsive_) return;
    if (echo_) out = token + delimiter;
    if (!reject_next_.empty()) {  // a unit refusing a command: nothing is executed
      out += "! " + reject_next_ + "\r\n";
      reject_next_.clear();
    } else {
      out += Answer(command) + "\r\n";
    }
  }
  Send(out);
}

std::string PtuEmulator::Answer(const std::string& command) {
  auto ok = [] { return std::string("*"); };
  if (command == "ED" || command == "EE") {
    echo_ = command == "EE";
    return ok();
  }
  if (command == "FT" || command == "FV") {
    verbose_ = command == "FV";
    return ok();
  }
  if (command == "CI" || command == "CV") {
    velocity_mode_ = command == "CV";
    for (Axis* a : {&pan_, &tilt_})
      a->target = a->position;
    return ok();
  }
  if (command == "H" || command == "HP" || command == "HT") {
    for (Axis* a : {&pan_, &tilt_}) {
      if (command.size() == 2 && command[1] != a->name) continue;
      a->target = a->position;
      if (velocity_mode_) a->speed = 0.0;
    }
    return ok();
  }
  if (command == "I") return ok();
  if (command == "A") {
    double wait = 0.0;
    for (const Axis* a : {&pan_, &tilt_}) {
      if (!velocity_mode_ && a->speed > 0.0) {
        wait = std::max(wait, std::abs(a->target - a->position) / a->speed);
      }
    }
    AdvanceLocked(wait);
    return ok();
  }
  if (command == "E") return verbose_ ? "* Echoing is " + std::string(echo_ ? "ON" : "OFF") : "*";
  if (command == "C") {
    return std::string("* ") + (velocity_mode_ ? "Pure velocity control mode"
                                               : "Independent position/speed control mode");
  }
  if (command == "V") return "* Pan-Tilt Controller emulator (linetrack)";
  if (command.size() >= 2 && (command[0] == 'P' || command[0] == 'T')) {
    return AxisCommand(command[0] == 'P' ? pan_ : tilt_, command[1], command.substr(2));
  }
  return "! Illegal Command";
}

std::string PtuEmulator::AxisCommand(Axis& axis, char op, const std::string& argument) {
  char text[128];
  const std::string word = axis.word;
  auto reply = [&](long value, const std::string& verbose) {
    return verbose_ ? "* " + verbose : "* " + std::to_string(value);
  };
  if (argument.empty()) {
    switch (op) {
      case 'P':
        return reply(std::lround(axis.position), "Current " + word + " position is " +
                                                     std::to_string(std::lround(axis.position)));
      case 'S':
        return reply(std::lround(axis.speed), "Current " + word + " speed is " +
                                                  std::to_string(std::lround(axis.speed)) +
                                                  " positions/sec");
      case 'R':
        std::snprintf(text, sizeof(text), "%.4f", axis.resolution);
        return verbose_ ? "* " + std::string(text) + " seconds arc per " + word + " position"
                        : "* " + std::string(text);
      case 'N':
        return reply(axis.min, "Minimum " + word + " position is " + std::to_string(axis.min));
      case 'X':
        return reply(axis.max, "Maximum " + word + " position is " + std::to_string(axis.max));
      case 'U':
        return reply(axis.max_speed, "Maximum " + word + " speed is " +
                                         std::to_string(axis.max_speed) + " positions/sec");
      case 'L':
        return reply(options_.min_speed, "Minimum " + word + " speed is " +
                                             std::to_string(options_.min_speed) + " positions/sec");
      default:
        return "! Illegal Command";
    }
  }
  long value = 0;
  if (op != 'P' && op != 'O' && op != 'S') return "! Illegal Command";
  if (!ParseInteger(argument, &value)) return "! Illegal Command Argument";
  if (op == 'P' || op == 'O') {
    if (velocity_mode_) return "! Position commands need independent control mode (CI)";
    const double target = op == 'P' ? static_cast<double>(value) : axis.position + value;
    if (target > axis.max) {
      return "! Maximum allowable " + word + " position is " + std::to_string(axis.max);
    }
    if (target < axis.min) {
      return "! Minimum allowable " + word + " position is " + std::to_string(axis.min);
    }
    axis.target = target;
    return "*";
  }
  // Speed: a magnitude in independent mode, a signed velocity in pure velocity mode.
  if (std::labs(value) > axis.max_speed) {
    return "! " + word + " speed cannot exceed " + std::to_string(axis.max_speed) +
           " positions/sec";
  }
  if (!velocity_mode_ && value < options_.min_speed) {
    return "! Motor speed cannot be less than " + std::to_string(options_.min_speed) + " pos/sec";
  }
  axis.speed = static_cast<double>(value);
  return "*";
}

void PtuEmulator::AdvanceLocked(double seconds) {
  time_ += seconds;
  std::string events;
  for (Axis* a : {&pan_, &tilt_}) {
    if (velocity_mode_) {
      const double next = a->position + a->speed * seconds;
      const bool over = next >= a->max && a->speed > 0.0;
      const bool under = next <= a->min && a->speed < 0.0;
      a->position = std::clamp(next, static_cast<double>(a->min), static_cast<double>(a->max));
      if (over || under) {
        a->speed = 0.0;
        events += std::string("!") + a->name;
      }
      a->target = a->position;
    } else {
      const double to_go = a->target - a->position;
      const double step = std::abs(a->speed) * seconds;
      a->position = std::abs(to_go) <= step ? a->target : a->position + std::copysign(step, to_go);
    }
  }
  if (!events.empty() && responsive_) {
    // Written under the state lock so that an event cannot cut into a reply line.
    Send(events);
  }
}

void PtuEmulator::Advance(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  AdvanceLocked(seconds);
}

double PtuEmulator::time() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return time_;
}

void PtuEmulator::SetResponsive(bool responsive) {
  std::lock_guard<std::mutex> lock(mutex_);
  responsive_ = responsive;
}

void PtuEmulator::RejectNextCommand(const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  reject_next_ = message;
}

void PtuEmulator::Inject(const std::string& bytes) {
  std::lock_guard<std::mutex> lock(mutex_);
  Send(bytes);
}

double PtuEmulator::pan_position() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pan_.position;
}

double PtuEmulator::tilt_position() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tilt_.position;
}

double PtuEmulator::pan_speed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pan_.speed;
}

bool PtuEmulator::velocity_mode() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return velocity_mode_;
}

std::vector<std::string> PtuEmulator::commands() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return commands_;
}

void PtuEmulator::SetPositions(double pan_counts, double tilt_counts) {
  std::lock_guard<std::mutex> lock(mutex_);
  pan_.position = pan_.target = pan_counts;
  tilt_.position = tilt_.target = tilt_counts;
}

}  // namespace linetrack

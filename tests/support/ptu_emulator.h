// An emulated PTU-D46 on a pseudo-terminal, for tests and demos without the hardware: a thread
// answers the ASCII protocol subset of ptu_protocol.h on the master side; the driver opens the
// slave (device_path()) as it would /dev/ttyUSB0. The emulator's clock only moves when told
// (Advance, or a fixed time per command), so tests are deterministic.
//
// Behaviour: power-up with echo on and verbose feedback, independent position mode; positions
// and speeds in counts; limits enforced for position commands ("! Maximum allowable Pan
// position is 3090"); in independent mode an axis moves towards its target at its speed (no
// acceleration); in pure velocity mode it moves at its signed speed and, on reaching a limit,
// stops and sends "!P" or "!T" (no line terminator, as the manual shows it).
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace linetrack {

struct PtuEmulatorOptions {
  double pan_resolution_arcsec = 185.1428;  // PR: a D46 in half-step mode
  double tilt_resolution_arcsec = 185.1428;
  long pan_min = -3090, pan_max = 3090;              // PN, PX (counts): about +-159 degrees
  long tilt_min = -907, tilt_max = 604;              // TN, TX: about -47 .. +31 degrees
  long pan_max_speed = 2902, tilt_max_speed = 2902;  // PU, TU (counts/s)
  long min_speed = 31;               // PL, TL: lowest speed of independent-mode moves (counts/s)
  long initial_speed = 1000;         // PS, TS at power-up
  double seconds_per_command = 0.0;  // the clock advances this much per command received
};

class PtuEmulator {
 public:
  // Opens a pseudo-terminal and starts answering; nullptr with *why set on failure.
  static std::unique_ptr<PtuEmulator> Start(const PtuEmulatorOptions& options, std::string* why);
  ~PtuEmulator();
  PtuEmulator(const PtuEmulator&) = delete;
  PtuEmulator& operator=(const PtuEmulator&) = delete;

  // The slave side, to open like a serial port ("/dev/pts/N").
  const std::string& device_path() const { return device_path_; }

  // Moves the emulated clock forward by `seconds` and the axes with it.
  void Advance(double seconds);
  double time() const;

  // When false, commands are read and dropped without any reply (a hung unit).
  void SetResponsive(bool responsive);
  // The next command received is answered "! <message>" and not executed (error replies in the
  // middle of a run: a unit that refuses, a command garbled on the line).
  void RejectNextCommand(const std::string& message);
  // Sends raw bytes to the host (noise, banners, unsolicited events).
  void Inject(const std::string& bytes);

  // Ground truth, in counts and counts/s.
  double pan_position() const;
  double tilt_position() const;
  double pan_speed() const;  // signed in velocity mode
  bool velocity_mode() const;
  // Every command received, upper-cased, in order.
  std::vector<std::string> commands() const;

  // Puts an axis somewhere (tests: start near a limit).
  void SetPositions(double pan_counts, double tilt_counts);

 private:
  struct Axis {
    char name = 'P';  // 'P' or 'T'
    const char* word = "Pan";
    double position = 0.0;  // counts
    double target = 0.0;    // independent mode
    double speed = 0.0;     // counts/s: magnitude (independent) or signed (velocity mode)
    long min = 0, max = 0, max_speed = 0;
    double resolution = 0.0;
  };

  explicit PtuEmulator(const PtuEmulatorOptions& options);
  void Run();
  void Handle(const std::string& token, char delimiter);
  std::string Answer(const std::string& command);
  std::string AxisCommand(Axis& axis, char op, const std::string& argument);
  void AdvanceLocked(double seconds);
  void Send(const std::string& bytes);

  PtuEmulatorOptions options_;
  int master_ = -1;
  int slave_ = -1;  // kept open so the line stays configured and never hangs up
  std::string device_path_;

  mutable std::mutex mutex_;  // state below
  Axis pan_, tilt_;
  bool velocity_mode_ = false;
  bool echo_ = true;
  bool verbose_ = true;
  bool responsive_ = true;
  std::string reject_next_;
  double time_ = 0.0;
  std::vector<std::string> commands_;

  std::mutex write_mutex_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace linetrack

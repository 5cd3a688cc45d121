// Aravis' fake GigE Vision camera (arv-fake-gv-camera-0.8, Debian package aravis-tools) run as a
// child process: the real GigE Vision protocol over the loopback interface, for tests and for
// `linetrack bench capture`. Default 512x512 Mono8 at 25 fps; frame ids start near 65400 and wrap
// from 65535 to 1; a Mono8 frame with id k holds I(x, y) = (x + y + k) mod 255.
#pragma once

#include <sys/types.h>

#include <string>

namespace linetrack {

struct FakeGigECameraOptions {
  std::string serial = "LINETRACK0";  // serial number (the Aravis id is Aravis-Fake-SERIAL)
  std::string interface_address = "127.0.0.1";
  std::string executable = "arv-fake-gv-camera-0.8";  // looked up in PATH
  double discovery_timeout_s = 10.0;  // longest wait for Aravis discovery to see the camera
};

// Owns one fake camera process. Not copyable; the destructor stops the process.
class FakeGigECamera {
 public:
  explicit FakeGigECamera(const FakeGigECameraOptions& options = {});
  ~FakeGigECamera();
  FakeGigECamera(const FakeGigECamera&) = delete;
  FakeGigECamera& operator=(const FakeGigECamera&) = delete;

  // Spawns the process and polls Aravis discovery (about one second per round) until the
  // camera's serial appears or the timeout passes. False with *why set on failure (executable
  // missing, process exited, e.g. because another fake camera holds the GVCP port 3956).
  bool Start(std::string* why);

  // SIGKILL, as when a camera is unplugged, then reaps the process.
  void Kill();
  // SIGTERM, waits up to one second, then SIGKILL.
  void Stop();

  bool running() const { return pid_ > 0; }
  const FakeGigECameraOptions& options() const { return options_; }

 private:
  void Reap(bool force);

  FakeGigECameraOptions options_;
  pid_t pid_ = -1;
};

// True when Aravis discovery lists a device with this serial number (one discovery round).
bool AravisSeesSerial(const std::string& serial);

}  // namespace linetrack

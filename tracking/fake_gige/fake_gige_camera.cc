#include "tracking/fake_gige/fake_gige_camera.h"

#include <arv.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

extern char** environ;

namespace linetrack {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

bool AravisSeesSerial(const std::string& serial) {
  arv_update_device_list();
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    const char* s = arv_get_device_serial_nbr(i);
    if (s != nullptr && serial == s) return true;
  }
  return false;
}

FakeGigECamera::FakeGigECamera(const FakeGigECameraOptions& options) : options_(options) {}

FakeGigECamera::~FakeGigECamera() {
  Stop();
}

bool FakeGigECamera::Start(std::string* why) {
  if (running()) return true;
  std::vector<std::string> args = {options_.executable, "-i", options_.interface_address, "-s",
                                   options_.serial};
  std::vector<char*> argv;
  for (std::string& a : args)
    argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The fake camera logs to stdout/stderr: keep the caller's output clean.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc =
      posix_spawnp(&pid, options_.executable.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    *why = "cannot run " + options_.executable + ": " + std::strerror(rc) +
           " (Debian package aravis-tools)";
    return false;
  }
  pid_ = pid;

  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(options_.discovery_timeout_s));
  while (Clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      *why = options_.executable + " exited at start (another fake camera on " +
             options_.interface_address + ":3956?)";
      return false;
    }
    if (AravisSeesSerial(options_.serial)) return true;  // one discovery round: about 1 s
  }
  Stop();
  *why = "Aravis did not discover the fake camera " + options_.serial + " within " +
         std::to_string(options_.discovery_timeout_s) + " s";
  return false;
}

void FakeGigECamera::Kill() {
  if (!running()) return;
  kill(pid_, SIGKILL);
  Reap(/*force=*/true);
}

void FakeGigECamera::Stop() {
  if (!running()) return;
  kill(pid_, SIGTERM);
  Reap(/*force=*/false);
}

void FakeGigECamera::Reap(bool force) {
  const auto deadline = Clock::now() + std::chrono::seconds(1);
  int status = 0;
  while (!force && Clock::now() < deadline) {
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, &status, 0);
  pid_ = -1;
}

}  // namespace linetrack

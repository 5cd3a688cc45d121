// A ROS master of the process's own: roscore on a free port of 127.0.0.1 with its own ROS_HOME,
// never the machine's default master (`bench ros` and the ROS tests), child processes, and
// waiting on a condition with a deadline instead of sleeping.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace linetrack::app {

// Waits until `done` holds or `seconds` pass, polling every millisecond (the condition is what
// synchronises; the poll interval only bounds the CPU spent). True when it held.
bool WaitFor(const std::function<bool()>& done, double seconds);

// A TCP port of 127.0.0.1 free when asked (the kernel's choice for port 0); -1 on failure.
int FreeLoopbackPort();

// True when something accepts TCP connections on 127.0.0.1:port.
bool PortAccepts(int port);

// A child process started with the current environment (PATH searched); SIGINT and reaped on
// Stop() or destruction.
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& argv);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0 || exit_status_ != -1; }
  // True while the process has not exited.
  bool Running();
  // SIGINT, then SIGKILL when it has not exited within `seconds`; returns the wait status.
  int Stop(double seconds = 15.0);

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
};

// roscore on a free port of 127.0.0.1; ROS_MASTER_URI, ROS_HOME (`home`, created) and ROS_IP set
// in this process's environment for itself and its children. Stopped on destruction.
class RosCore {
 public:
  explicit RosCore(const std::filesystem::path& home);
  bool ready() const { return ready_; }
  const std::string& uri() const { return uri_; }

 private:
  int port_ = -1;
  std::string uri_;
  std::unique_ptr<ChildProcess> process_;
  bool ready_ = false;
};

}  // namespace linetrack::app

// linetrack_cli_server FD: runs `linetrack` jobs for the CLI tests. The `linetrack` binary loads
// some 300 shared libraries at each start (ViSP, OpenCV, ROS and theirs, bound at load time), which
// costs more than most test runs themselves; this server loads them once and forks a child per
// request, which runs the very RunLinetrack() of the binary's main() with the request's arguments,
// environment, working folder and output files, and exits with its exit code. The server itself
// never runs a job, so each child starts from a process that has only loaded the libraries.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/cli.h"
#include "tests/support/cli_protocol.h"

namespace {

using linetrack::test_support::CliRequest;

// Points file descriptor `target` at `path` (created or truncated); false on failure.
bool Redirect(const std::string& path, int target) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  const bool ok = dup2(fd, target) == target;
  close(fd);
  return ok;
}

// In the forked child: sets up the request's process state, runs it and exits with its code.
[[noreturn]] void RunInChild(CliRequest* request) {
  if (chdir(request->working_dir.c_str()) != 0 || !Redirect(request->stdout_path, 1) ||
      !Redirect(request->stderr_path, 2)) {
    std::perror("linetrack_cli_server: cannot set up the run");
    std::_Exit(127);
  }
  clearenv();
  for (std::string& entry : request->environment)
    putenv(entry.data());
  std::vector<char*> argv;
  for (std::string& argument : request->argv)
    argv.push_back(argument.data());
  argv.push_back(nullptr);
  std::exit(linetrack::app::RunLinetrack(static_cast<int>(request->argv.size()), argv.data()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: linetrack_cli_server SOCKET_FD\n");
    return 2;
  }
  const int socket_fd = std::atoi(argv[1]);
  CliRequest request;
  while (linetrack::test_support::ReceiveRequest(socket_fd, &request)) {
    std::fflush(nullptr);  // nothing buffered may be written twice
    const pid_t child = fork();
    if (child == 0) {
      close(socket_fd);
      RunInChild(&request);
    }
    int status = 0;
    pid_t waited = -1;
    do {
      waited = child > 0 ? waitpid(child, &status, 0) : -1;
    } while (waited < 0 && errno == EINTR);
    const int code = waited == child && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (!linetrack::test_support::SendExitCode(socket_fd, code)) break;
  }
  return 0;
}

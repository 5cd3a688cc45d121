// The wire format between the CLI tests and linetrack_cli_server (cli_server.cc): lists of strings
// over a Unix stream socket, each as a 32-bit count then, per string, a 32-bit length and its
// bytes.
#pragma once

#include <string>
#include <vector>

namespace linetrack::test_support {

// One run of `linetrack`: its arguments (argv[0] first), environment ("NAME=value"), working folder
// and the files its stdout and stderr go to.
struct CliRequest {
  std::vector<std::string> argv;
  std::vector<std::string> environment;
  std::string working_dir, stdout_path, stderr_path;
};

// Writes or reads one request; false when the socket fails or closes.
bool SendRequest(int fd, const CliRequest& request);
bool ReceiveRequest(int fd, CliRequest* request);

// The reply: the run's exit code, -1 when a signal ended it.
bool SendExitCode(int fd, int code);
bool ReceiveExitCode(int fd, int* code);

}  // namespace linetrack::test_support

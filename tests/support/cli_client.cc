#include "tests/support/cli_client.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <wordexp.h>

#include <cstdio>
#include <filesystem>
#include <vector>

#include "tests/support/cli_protocol.h"

extern char** environ;

namespace linetrack::test_support {

namespace {

// The server child process and the socket to it; stopped (socket closed, child reaped) at exit.
class CliServer {
 public:
  explicit CliServer(const std::string& path) {
    int sockets[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) return;
    // The server's end becomes its descriptor kServerFd, which dup2 leaves open across exec.
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, sockets[1], kServerFd);
    const std::string fd_text = std::to_string(kServerFd);
    char* argv[] = {const_cast<char*>(path.c_str()), const_cast<char*>(fd_text.c_str()), nullptr};
    const bool spawned = sockets[1] != kServerFd &&
                         posix_spawn(&pid_, path.c_str(), &actions, nullptr, argv, environ) == 0;
    posix_spawn_file_actions_destroy(&actions);
    close(sockets[1]);
    if (spawned) {
      fd_ = sockets[0];
    } else {
      close(sockets[0]);
      pid_ = -1;
    }
  }
  ~CliServer() {
    if (fd_ >= 0) close(fd_);
    if (pid_ > 0) waitpid(pid_, nullptr, 0);
  }
  CliServer(const CliServer&) = delete;
  CliServer& operator=(const CliServer&) = delete;

  std::optional<int> Run(const CliRequest& request) {
    int code = -1;
    if (fd_ < 0 || !SendRequest(fd_, request) || !ReceiveExitCode(fd_, &code)) {
      return std::nullopt;
    }
    return code;
  }

 private:
  static constexpr int kServerFd = 3;
  int fd_ = -1;
  pid_t pid_ = -1;
};

// The words of `args` as the shell would split them, or nothing when only a shell can run them.
std::optional<std::vector<std::string>> ShellWords(const std::string& args) {
  wordexp_t words;
  if (wordexp(args.c_str(), &words, WRDE_NOCMD) != 0) return std::nullopt;
  std::vector<std::string> result(words.we_wordv, words.we_wordv + words.we_wordc);
  wordfree(&words);
  return result;
}

}  // namespace

std::optional<int> RunThroughCliServer(const std::string& server_path, const std::string& args,
                                       const std::string& stdout_path,
                                       const std::string& stderr_path) {
  std::optional<std::vector<std::string>> words = ShellWords(args);
  if (!words) return std::nullopt;
  static CliServer server(server_path);
  CliRequest request;
  request.argv.push_back("linetrack");
  request.argv.insert(request.argv.end(), words->begin(), words->end());
  for (char** entry = environ; *entry != nullptr; ++entry)
    request.environment.push_back(*entry);
  request.working_dir = std::filesystem::current_path().string();
  request.stdout_path = stdout_path;
  request.stderr_path = stderr_path;
  std::fflush(nullptr);
  return server.Run(request);
}

}  // namespace linetrack::test_support

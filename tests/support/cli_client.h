// The CLI tests' side of linetrack_cli_server: one server per test process, started at the first
// run and stopped when the process exits.
#pragma once

#include <optional>
#include <string>

namespace linetrack::test_support {

// Runs `linetrack ARGS` through the server at `server_path`, with this process's environment and
// working folder, stdout and stderr to the given files. ARGS are split as a shell splits a
// command's words (wordexp: quotes, variables, globs); returns std::nullopt when they hold what
// only a shell does (redirections, pipes, command substitution) or the server cannot run, so that
// the caller runs the binary through the shell instead. The exit code is -1 when a signal ended it.
std::optional<int> RunThroughCliServer(const std::string& server_path, const std::string& args,
                                       const std::string& stdout_path,
                                       const std::string& stderr_path);

}  // namespace linetrack::test_support

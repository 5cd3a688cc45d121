// Support for tests that run the `linetrack` binary (LINETRACK_EXE, a compile definition of the
// test target): a fresh scratch folder per test and a runner that captures the exit code, stdout
// and stderr. With LINETRACK_CLI_SERVER (linetrack_test_runs_cli in tests/CMakeLists.txt) the runs
// go through linetrack_cli_server (cli_server.cc), which runs the binary's own code without
// loading its libraries again for every run.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "tests/support/cli_client.h"

namespace linetrack::test_support {

// What one run of the binary produced.
struct CommandRun {
  int code = -1;  // exit code; -1 when killed by a signal
  std::string out, err;
};

inline std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Fixture with an empty folder test_output/<Suite>.<Test> in the build tree (unique per test:
// ctest runs tests of different suites in parallel).
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::path(LINETRACK_BINARY_DIR) / "test_output" /
           (std::string(info->test_suite_name()) + "." + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }

  // Runs `linetrack ARGS` (ARGS as a shell would split them), capturing stdout and stderr: through
  // the CLI server when the test has one, else the binary itself.
  CommandRun Linetrack(const std::string& args) const { return Run(args, Runner::kServer); }

  // The same, always through the binary.
  CommandRun LinetrackBinary(const std::string& args) const { return Run(args, Runner::kBinary); }

  std::filesystem::path dir_;

 private:
  enum class Runner { kServer, kBinary };

  CommandRun Run(const std::string& args, Runner runner) const {
    const std::filesystem::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    std::optional<int> code;
#ifdef LINETRACK_CLI_SERVER
    if (runner == Runner::kServer) {
      code = RunThroughCliServer(LINETRACK_CLI_SERVER, args, out.string(), err.string());
    }
#else
    (void)runner;
#endif
    if (!code) {
      const std::string command =
          std::string(LINETRACK_EXE) + " " + args + " > " + out.string() + " 2> " + err.string();
      const int status = std::system(command.c_str());
      code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    CommandRun run;
    run.code = *code;
    run.out = ReadAll(out);
    run.err = ReadAll(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return run;
  }
};

}  // namespace linetrack::test_support

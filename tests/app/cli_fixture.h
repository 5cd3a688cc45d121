// Running the `linetrack` binary from the app tests: a fresh output folder per test and a runner
// capturing the exit code, stdout and stderr of `linetrack ARGS`. LINETRACK_EXE names the binary.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace linetrack::testing {

struct CommandRun {
  int code = -1;
  std::string out, err;
};

inline std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(LINETRACK_BINARY_DIR) / "test_output" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }

  // Runs `linetrack ARGS`, capturing stdout and stderr.
  CommandRun Linetrack(const std::string& args) {
    const std::string out = (dir_ / "stdout.txt").string(), err = (dir_ / "stderr.txt").string();
    const std::string cmd = std::string(LINETRACK_EXE) + " " + args + " > " + out + " 2> " + err;
    const int status = std::system(cmd.c_str());
    CommandRun run;
    run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.out = ReadAll(out);
    run.err = ReadAll(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return run;
  }

  std::filesystem::path dir_;
};

}  // namespace linetrack::testing

// Every file of the malformed corpus is refused with one InputError naming the file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "models/cao_reader.h"
#include "models/errors.h"

namespace linetrack {
namespace {

const std::string kCorpus = std::string(LINETRACK_SOURCE_DIR) + "/tests/data/cao_malformed";

TEST(CaoMalformed, EveryFileGivesOneLocatedError) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kCorpus)) {
    const std::string path = entry.path().string();
    ++files;
    try {
      ReadCao(path);
      ADD_FAILURE() << path << " was accepted";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path, 0), 0u) << message;  // starts with the file name
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      if (entry.file_size() > 0) {
        EXPECT_TRUE(std::regex_search(message, std::regex("\\.cao:[0-9]+: "))) << message;
      }
    }
  }
  EXPECT_GE(files, 20);
}

TEST(CaoMalformed, ErrorsPointAtTheRightLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"nan_coordinate.cao", ":4: point 1: not a finite number: 'nan'"},
      {"truncated_points.cao", ":5: file ends early: expected point 3"},
      {"face_index_out_of_range.cao", ":9: face from points 0: index 5 out of range (0..2)"},
      {"face_lines_not_closed.cao", ":12: face from lines 0: its lines do not form a closed chain"},
      {"huge_count.cao", ":2: the number of points exceeds 100000"},
  };
  for (const auto& [file, expected] : cases) {
    const std::string path = kCorpus + "/" + file;
    try {
      ReadCao(path);
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), path + expected);
    }
  }
}

}  // namespace
}  // namespace linetrack

// The line CSV's parser (app/lines_csv.h): the rows `linetrack lines` writes read back exactly,
// and every malformed row is one line naming the file and the line.
#include "app/lines_csv.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "models/errors.h"

namespace linetrack::app {
namespace {

const std::string kPath = "dir/lines.csv";

// The message of the InputError that parsing `text` throws ("" when it parses).
std::string ErrorOf(const std::string& text) {
  try {
    ParseLinesCsv(text, kPath);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LinesCsv, ReadsRowsWithHeaderCommentsBlanksAndCrLf) {
  const std::vector<Segment2> lines = ParseLinesCsv(
      "u1,v1,u2,v2\r\n12.5,30.25,200,31\r\n# comment\n\n \t\n  640 , 0,639.5,479.875\n-1e2,3E1,0,7",
      kPath);
  const std::vector<Segment2> expected = {{{12.5, 30.25}, {200.0, 31.0}},
                                          {{640.0, 0.0}, {639.5, 479.875}},
                                          {{-100.0, 30.0}, {0.0, 7.0}}};
  ASSERT_EQ(lines.size(), expected.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines[i].a, expected[i].a) << i;  // decimal values exact in binary: no tolerance
    EXPECT_EQ(lines[i].b, expected[i].b) << i;
  }
}

TEST(LinesCsv, FirstRowIsDataWhenAllNumbers) {
  const std::vector<Segment2> lines = ParseLinesCsv("1,2,3,4\n5,6,7,8\n", kPath);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].a, Eigen::Vector2d(1.0, 2.0));
  EXPECT_EQ(lines[1].b, Eigen::Vector2d(7.0, 8.0));
}

TEST(LinesCsv, EachMalformedRowNamesFileAndLine) {
  const struct {
    std::string text, error;
  } cases[] = {
      {"u1,v1,u2,v2\n1,2,3\n", "dir/lines.csv:2: expected 4 numbers (u1,v1,u2,v2), got 3"},
      {"1,2,3,4\n1,2,3,4,5\n", "dir/lines.csv:2: expected 4 numbers (u1,v1,u2,v2), got 5"},
      {"1,2,3,4\n1,2,3,4,\n", "dir/lines.csv:2: expected 4 numbers (u1,v1,u2,v2), got 5"},
      {"1,2,3,4\n\n1,2,x,4\n", "dir/lines.csv:3: not a number: 'x'"},
      {"1,2,3,4\n1,2,3 4,5\n", "dir/lines.csv:2: not a number: '3 4'"},
      {"1,2,3,4\n1,,3,4\n", "dir/lines.csv:2: not a number: ''"},
      {"1,2,3,4\n1,2,nan,4\n", "dir/lines.csv:2: not a finite number: 'nan'"},
      {"1,2,3,4\n1,2,3,1e999\n", "dir/lines.csv:2: not a number: '1e999'"},
      {"u1,v1,u2,v2\nu1,v1,u2,v2\n", "dir/lines.csv:2: not a number: 'u1'"},
      {"", "dir/lines.csv: no line segments"},
      {"u1,v1,u2,v2\n# none\n\n", "dir/lines.csv: no line segments"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string error = ErrorOf(c.text);
    EXPECT_EQ(error, c.error);
    EXPECT_EQ(error.find('\n'), std::string::npos);
  }
}

TEST(LinesCsv, MissingFileNamesIt) {
  try {
    ReadLinesCsv("/nonexistent/lines.csv");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/lines.csv: no such lines file");
  }
}

}  // namespace
}  // namespace linetrack::app

// Calibration patterns: which board, its size, and where its points lie on the board plane.
// Board frame: origin at the first inner corner (or dot), x along a row (cols), y down the
// columns (rows), z = 0 on the board; point (row i, col j) is at (j s, i s, 0), index i cols + j.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace linetrack {

enum class PatternKind { kChessboard, kCircles, kCharuco };

// "chessboard", "circles", "charuco".
const char* ToString(PatternKind kind);

// The kind a name gives (the names above), or nullopt.
std::optional<PatternKind> ParsePatternKind(const std::string& name);

struct PatternSpec {
  PatternKind kind = PatternKind::kChessboard;
  int cols = 9;           // inner corners per row (chessboard, ChArUco) or dots per row (circles)
  int rows = 6;           // inner corners per column or dots per column
  double square = 0.025;  // square side or dot spacing, metres
  // ChArUco only: marker side (metres; 0 means 0.7 square) and OpenCV's predefined dictionary.
  double marker = 0.0;
  std::string dictionary = "DICT_4X4_50";

  // Sizes at least 2 (3 for ChArUco squares), positive finite lengths, marker smaller than the
  // square, a known dictionary with enough markers for the board.
  bool Check(std::string* why) const;

  int PointCount() const { return cols * rows; }
  double MarkerSide() const { return marker > 0.0 ? marker : 0.7 * square; }
};

// "the chessboard pattern (9x6) was found in none of the N images": why a calibration has no view.
std::string PatternNeverFoundMessage(const PatternSpec& pattern, size_t images);

// The pattern's points in the board frame (metres), index i cols + j.
std::vector<Eigen::Vector3d> BoardPoints(const PatternSpec& pattern);

// OpenCV's predefined ArUco dictionary id for a name like "DICT_4X4_50", or -1.
int ArucoDictionaryId(const std::string& name);

}  // namespace linetrack

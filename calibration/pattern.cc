#include "calibration/pattern.h"

#include <cmath>
#include <opencv2/aruco.hpp>
#include <utility>

namespace linetrack {
namespace {

const std::pair<const char*, int> kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
    {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
    {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
    {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
    {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
    {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
    {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
    {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
    {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
};

// Markers a dictionary holds (the number at the end of its name; 1024 for the original).
int DictionarySize(const std::string& name) {
  if (name == "DICT_ARUCO_ORIGINAL") return 1024;
  return std::stoi(name.substr(name.rfind('_') + 1));
}

}  // namespace

const char* ToString(PatternKind kind) {
  switch (kind) {
    case PatternKind::kChessboard:
      return "chessboard";
    case PatternKind::kCircles:
      return "circles";
    case PatternKind::kCharuco:
      return "charuco";
  }
  return "?";
}

std::optional<PatternKind> ParsePatternKind(const std::string& name) {
  for (PatternKind k : {PatternKind::kChessboard, PatternKind::kCircles, PatternKind::kCharuco}) {
    if (name == ToString(k)) return k;
  }
  return std::nullopt;
}

int ArucoDictionaryId(const std::string& name) {
  for (const auto& [n, id] : kDictionaries) {
    if (name == n) return id;
  }
  return -1;
}

bool PatternSpec::Check(std::string* why) const {
  if (cols < 2 || rows < 2 || cols > 1000 || rows > 1000) {
    *why = "--cols and --rows must be between 2 and 1000";
    return false;
  }
  if (kind == PatternKind::kChessboard && cols == rows) {
    // A square board of corners has no distinguishable orientation: OpenCV may flip it.
    *why = "--cols and --rows must differ for a chessboard (its orientation would be ambiguous)";
    return false;
  }
  if (!std::isfinite(square) || square <= 0.0 || square > 10.0) {
    *why = "--square must be a positive length in metres (at most 10)";
    return false;
  }
  if (kind == PatternKind::kCharuco) {
    if (!std::isfinite(marker) || marker < 0.0 || MarkerSide() >= square) {
      *why = "--marker must be positive and smaller than --square";
      return false;
    }
    if (ArucoDictionaryId(dictionary) < 0) {
      *why = "--dictionary: unknown ArUco dictionary '" + dictionary + "'";
      return false;
    }
    const int markers = ((cols + 1) * (rows + 1)) / 2;
    if (markers > DictionarySize(dictionary)) {
      *why = "--dictionary " + dictionary + " has fewer markers than the board needs (" +
             std::to_string(markers) + ")";
      return false;
    }
  }
  return true;
}

std::string PatternNeverFoundMessage(const PatternSpec& pattern, size_t images) {
  return std::string("the ") + ToString(pattern.kind) + " pattern (" +
         std::to_string(pattern.cols) + "x" + std::to_string(pattern.rows) +
         ") was found in none of the " + std::to_string(images) + " images";
}

std::vector<Eigen::Vector3d> BoardPoints(const PatternSpec& pattern) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<size_t>(pattern.PointCount()));
  for (int i = 0; i < pattern.rows; ++i) {
    for (int j = 0; j < pattern.cols; ++j)
      points.emplace_back(j * pattern.square, i * pattern.square, 0.0);
  }
  return points;
}

}  // namespace linetrack

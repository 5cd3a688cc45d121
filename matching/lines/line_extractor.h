// Line segments from grey images for the matcher: one interface over four detectors (the paper's
// Canny + oriented Hough, OpenCV's LSD, FastLineDetector and EdgeDrawing/EDLines), with
// undistortion by the camera's radial model, merging of collinear fragments, a minimum length
// and an optional region of interest. Output: segments in undistorted pixels (u = column).
#pragma once

#include <visp3/core/vpImage.h>
#include <functional>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "matching/lines/hough_lines.h"
#include "matching/lines/segment_fitting.h"
#include "matching/observed_line.h"
#include "models/camera.h"
#include "models/geometry.h"

namespace linetrack {

enum class LineDetectorKind {
  kHough,    // "hough": the paper's (RAS 2005, section 4.2), matching/lines/hough_lines.h
  kLsd,      // "lsd": cv::LineSegmentDetector (von Gioi et al.)
  kFld,      // "fld": cv::ximgproc::FastLineDetector (Lee et al. 2014)
  kEdlines,  // "edlines": cv::ximgproc::EdgeDrawing lines (Akinlar and Topal 2011)
};

// "hough", "lsd", "fld", "edlines"; ParseLineDetector returns nullopt for another name.
std::string LineDetectorName(LineDetectorKind kind);
std::optional<LineDetectorKind> ParseLineDetector(const std::string& name);
std::vector<LineDetectorKind> AllLineDetectors();

// How distortion is undone: endpoints of the segments found in the distorted image (free), or
// the image remapped before detection (one cv::remap per frame).
enum class UndistortionMode { kEndpoints, kImage };

// A rectangle of pixels (u = column, v = row); width or height 0: the whole image.
struct PixelRect {
  int u = 0, v = 0, width = 0, height = 0;
  bool Empty() const { return width <= 0 || height <= 0; }
};

// cv::ximgproc::FastLineDetector settings (thresholds set on rendered views, docs/lines.md).
struct FldOptions {
  double canny_low = 20.0, canny_high = 40.0;  // Canny thresholds (3x3 Sobel, L1)
  double distance_px = 1.414;                  // pixels off the fitted line end a segment
};

// cv::ximgproc::EdgeDrawing settings for its line detection.
struct EdlinesOptions {
  int gradient_threshold = 10;     // edge pixels need a gradient (Prewitt) above this
  int anchor_threshold = 4;        // anchors stand this much above their neighbours
  double sigma = 1.0;              // Gaussian smoothing (pixels)
  double line_fit_error_px = 1.0;  // largest RMS distance of a pixel chain from its line
  bool nfa_validation = true;      // a contrario validation of the lines
};

// cv::LineSegmentDetector settings.
struct LsdOptions {
  bool refine = true;  // LSD_REFINE_STD (split arcs into straight pieces) vs LSD_REFINE_NONE
  double scale = 0.8;  // image scale of the detection (Gaussian down-sampling)
};

// What LineExtractor does, in order: ROI, detection, undistortion, merging, minimum length.
struct LineExtractionOptions {
  LineDetectorKind detector = LineDetectorKind::kFld;  // the fastest that passes (docs/lines.md)
  double min_length_px = 20.0;           // segments shorter than this after merging are dropped
  double fragment_min_length_px = 10.0;  // shortest piece asked of the detector (before merging)
  bool merge = true;                     // merge collinear fragments (after undistortion)
  CollinearMergeOptions merge_options;
  // Pixels of the image the detector sees (the input image; the undistorted one with
  // UndistortionMode::kImage). Empty: the whole image.
  PixelRect roi;
  UndistortionMode undistortion = UndistortionMode::kEndpoints;
  // With a distorting camera: clip the segments to the undistorted image [0, w-1] x [0, h-1],
  // the frame model edges are projected into (barrel distortion shows more than that frame).
  bool clip_to_image = true;
  HoughLineOptions hough;
  FldOptions fld;
  EdlinesOptions edlines;
  LsdOptions lsd;

  // Finite, positive lengths; valid merge, ROI and detector settings.
  bool Check(std::string* why) const;
};

// One image's segments.
struct LineExtraction {
  std::vector<Segment2> segments;  // undistorted pixels, longest first
  int detected = 0;                // segments the detector returned (before merging, length)
};

// Extracts segments from images of one camera. Keeps its detector and buffers between frames:
// not thread-safe (one per thread).
class LineExtractor {
 public:
  // Without a camera, segments stay in the input image's pixels. Throws InputError when the
  // options or the camera are invalid.
  explicit LineExtractor(const LineExtractionOptions& options,
                         const std::optional<CameraIntrinsics>& camera = std::nullopt);
  ~LineExtractor();
  LineExtractor(LineExtractor&&) noexcept;
  LineExtractor& operator=(LineExtractor&&) noexcept;

  // Throws InputError when the image is empty, its size differs from the camera's, or the
  // region of interest leaves it; std::runtime_error when OpenCV fails.
  LineExtraction Extract(const vpImage<unsigned char>& image);
  LineExtraction Extract(const cv::Mat& grey);  // CV_8UC1

  // The segments alone: the extractor signature the tracker takes.
  std::vector<Segment2> operator()(const vpImage<unsigned char>& image) {
    return Extract(image).segments;
  }

  const LineExtractionOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Measurement noise of the extracted lines for the matcher (offset 1 px, angle 0.3 deg): FLD's
// detections of rendered model edges scatter by 0.3-0.5 px and 0.3 deg RMS (bench lines,
// docs/lines.md), doubled in offset for real images; the paper's 3 px / 1 deg (Table 1) is
// for its own noisier extraction. The focal-length error stays the paper's 2 %.
LineNoise DetectedLineNoise();

// A copyable callable around one LineExtractor (shared: not thread-safe), for code that takes
// `std::vector<Segment2>(const vpImage<unsigned char>&)`.
using LineExtractorFunction = std::function<std::vector<Segment2>(const vpImage<unsigned char>&)>;
LineExtractorFunction MakeLineExtractorFunction(
    const LineExtractionOptions& options,
    const std::optional<CameraIntrinsics>& camera = std::nullopt);

}  // namespace linetrack

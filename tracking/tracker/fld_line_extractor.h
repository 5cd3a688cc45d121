// An interim line extractor for the tracker's re-localisation until linetrack's own detector
// (matching/lines) is wired in: OpenCV's FastLineDetector (ximgproc, Lee et al. 2014) on the
// undistorted grey image, segments shorter than a minimum length dropped.
#pragma once

#include "tracking/tracker/relocalizer.h"

namespace linetrack {

struct FldExtractorOptions {
  double min_length_px = 25.0;           // shorter segments are dropped
  double distance_threshold_px = 1.414;  // FastLineDetector's merge distance
  double canny_low = 50.0, canny_high = 50.0;
  bool Check(std::string* why) const;
};

// A LineExtractor calling cv::ximgproc::FastLineDetector (one detector kept per extractor).
// Throws InputError on invalid options.
LineExtractor MakeFldLineExtractor(const FldExtractorOptions& options = {});

}  // namespace linetrack

#include "tracking/tracker/fld_line_extractor.h"

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>

#include "models/errors.h"

namespace linetrack {

bool FldExtractorOptions::Check(std::string* why) const {
  if (!(min_length_px >= 2.0) || !(distance_threshold_px > 0.0) || !(canny_low > 0.0) ||
      !(canny_high >= canny_low)) {
    *why = "FastLineDetector options: min length >= 2 px, positive thresholds, high >= low";
    return false;
  }
  return true;
}

LineExtractor MakeFldLineExtractor(const FldExtractorOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw InputError(why);
  std::shared_ptr<cv::ximgproc::FastLineDetector> detector = cv::ximgproc::createFastLineDetector(
      static_cast<int>(options.min_length_px), static_cast<float>(options.distance_threshold_px),
      options.canny_low, options.canny_high, 3, true);
  return [detector](const vpImage<unsigned char>& image) {
    const cv::Mat grey(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()),
                       CV_8UC1, const_cast<unsigned char*>(image.bitmap));
    std::vector<cv::Vec4f> found;
    detector->detect(grey, found);
    std::vector<Segment2> segments;
    segments.reserve(found.size());
    for (const cv::Vec4f& s : found) {
      segments.push_back(Segment2{Eigen::Vector2d(s[0], s[1]), Eigen::Vector2d(s[2], s[3])});
    }
    return segments;
  };
}

}  // namespace linetrack

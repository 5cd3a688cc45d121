#include "models/render/png.h"

#include <opencv2/imgcodecs.hpp>
#include <vector>

namespace linetrack {

std::string EncodePng(const vpImage<unsigned char>& image) {
  const cv::Mat view(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8U,
                     const_cast<unsigned char*>(image.bitmap));
  std::vector<unsigned char> bytes;
  cv::imencode(".png", view, bytes);
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace linetrack

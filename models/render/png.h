// PNG encoding of grey images in memory, so that the app can write files atomically.
#pragma once

#include <visp3/core/vpImage.h>
#include <string>

namespace linetrack {

// The PNG file content of `image` (8-bit grey, lossless).
std::string EncodePng(const vpImage<unsigned char>& image);

}  // namespace linetrack

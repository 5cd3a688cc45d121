#include "tracking/capture/pixel_convert.h"

#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace linetrack {
namespace {

// OpenCV names a Bayer pattern after the second row's second and third pixels, so GenICam's
// BayerRG (R G / G B) is OpenCV's BayerBG, and so on.
int OpenCvBayerToGrey(PixelKind kind) {
  switch (kind) {
    case PixelKind::kBayerRG:
      return cv::COLOR_BayerBG2GRAY;
    case PixelKind::kBayerGR:
      return cv::COLOR_BayerGB2GRAY;
    case PixelKind::kBayerGB:
      return cv::COLOR_BayerGR2GRAY;
    case PixelKind::kBayerBG:
      return cv::COLOR_BayerRG2GRAY;
    default:
      return -1;
  }
}

bool IsBayer(PixelKind kind) {
  return kind == PixelKind::kBayerRG || kind == PixelKind::kBayerGR ||
         kind == PixelKind::kBayerGB || kind == PixelKind::kBayerBG;
}

// Keeps the top 8 of the format's significant bits of `raw`'s little-endian 16-bit samples, into
// the rows of `dst` (width bytes each, no padding).
void Narrow16To8(const RawImage& raw, std::uint8_t* dst) {
  const int shift = raw.format.bits - 8;
  for (int y = 0; y < raw.height; ++y) {
    const std::uint8_t* s = raw.data + y * raw.stride_bytes;
    std::uint8_t* d = dst + static_cast<std::size_t>(y) * raw.width;
    for (int x = 0; x < raw.width; ++x) {
      const unsigned value =
          static_cast<unsigned>(s[2 * x]) | (static_cast<unsigned>(s[2 * x + 1]) << 8);
      const unsigned narrowed = value >> shift;
      d[x] = static_cast<std::uint8_t>(narrowed > 255u ? 255u : narrowed);
    }
  }
}

}  // namespace

int PixelFormat::BytesPerPixel() const {
  if (kind == PixelKind::kRgb || kind == PixelKind::kBgr) return 3;
  return bits > 8 ? 2 : 1;
}

bool PixelFormat::IsValid() const {
  if (bits < 8 || bits > 16) return false;
  if ((kind == PixelKind::kRgb || kind == PixelKind::kBgr) && bits != 8) return false;
  return true;
}

std::string PixelFormat::Name() const {
  std::string base;
  switch (kind) {
    case PixelKind::kMono:
      base = "Mono";
      break;
    case PixelKind::kBayerRG:
      base = "BayerRG";
      break;
    case PixelKind::kBayerGR:
      base = "BayerGR";
      break;
    case PixelKind::kBayerGB:
      base = "BayerGB";
      break;
    case PixelKind::kBayerBG:
      base = "BayerBG";
      break;
    case PixelKind::kRgb:
      base = "RGB";
      break;
    case PixelKind::kBgr:
      base = "BGR";
      break;
  }
  return base + std::to_string(bits);
}

bool ParsePixelFormatName(const std::string& name, PixelFormat* format) {
  static const struct {
    const char* prefix;
    PixelKind kind;
  } kPrefixes[] = {{"Mono", PixelKind::kMono},       {"BayerRG", PixelKind::kBayerRG},
                   {"BayerGR", PixelKind::kBayerGR}, {"BayerGB", PixelKind::kBayerGB},
                   {"BayerBG", PixelKind::kBayerBG}, {"RGB", PixelKind::kRgb},
                   {"BGR", PixelKind::kBgr}};
  for (const auto& p : kPrefixes) {
    const std::size_t n = std::strlen(p.prefix);
    if (name.compare(0, n, p.prefix) != 0) continue;
    const std::string digits = name.substr(n);
    if (digits.empty() || digits.size() > 2 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      return false;  // "Mono12Packed", "RGBa8", "Mono8Signed": not supported
    }
    PixelFormat parsed{p.kind, std::stoi(digits)};
    if (!parsed.IsValid()) return false;
    *format = parsed;
    return true;
  }
  return false;
}

bool ConvertToGrey(const RawImage& raw, vpImage<unsigned char>* grey, std::string* why) {
  if (!raw.format.IsValid()) {
    *why = "unsupported pixel format " + raw.format.Name();
    return false;
  }
  if (raw.width <= 0 || raw.height <= 0 || raw.data == nullptr) {
    *why = "empty image";
    return false;
  }
  const std::size_t row_bytes = static_cast<std::size_t>(raw.width) * raw.format.BytesPerPixel();
  if (raw.stride_bytes < row_bytes) {
    *why = "row stride " + std::to_string(raw.stride_bytes) + " < " + std::to_string(row_bytes) +
           " bytes";
    return false;
  }
  const std::size_t needed = raw.stride_bytes * (raw.height - 1) + row_bytes;
  if (raw.size_bytes < needed) {
    *why = "buffer of " + std::to_string(raw.size_bytes) + " bytes, " + std::to_string(raw.width) +
           "x" + std::to_string(raw.height) + " " + raw.format.Name() + " needs " +
           std::to_string(needed);
    return false;
  }
  if (grey->getWidth() != static_cast<unsigned>(raw.width) ||
      grey->getHeight() != static_cast<unsigned>(raw.height)) {
    grey->resize(raw.height, raw.width);
  }
  cv::Mat out(raw.height, raw.width, CV_8UC1, grey->bitmap);
  const PixelKind kind = raw.format.kind;
  const bool wide = raw.format.bits > 8;

  if (kind == PixelKind::kMono) {
    if (wide) {
      Narrow16To8(raw, grey->bitmap);
    } else {
      for (int y = 0; y < raw.height; ++y) {
        std::memcpy(grey->bitmap + static_cast<std::size_t>(y) * raw.width,
                    raw.data + y * raw.stride_bytes, raw.width);
      }
    }
    return true;
  }
  if (kind == PixelKind::kRgb || kind == PixelKind::kBgr) {
    const cv::Mat in(raw.height, raw.width, CV_8UC3, const_cast<std::uint8_t*>(raw.data),
                     raw.stride_bytes);
    cv::cvtColor(in, out, kind == PixelKind::kRgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
    return true;
  }
  if (IsBayer(kind)) {
    if (wide) {
      // Narrow first: the grey output has 8 bits anyway and the 8-bit demosaicing is faster.
      thread_local std::vector<std::uint8_t> narrow;
      narrow.resize(static_cast<std::size_t>(raw.width) * raw.height);
      Narrow16To8(raw, narrow.data());
      const cv::Mat in(raw.height, raw.width, CV_8UC1, narrow.data());
      cv::cvtColor(in, out, OpenCvBayerToGrey(kind));
    } else {
      const cv::Mat in(raw.height, raw.width, CV_8UC1, const_cast<std::uint8_t*>(raw.data),
                       raw.stride_bytes);
      cv::cvtColor(in, out, OpenCvBayerToGrey(kind));
    }
    return true;
  }
  *why = "unsupported pixel format " + raw.format.Name();
  return false;
}

}  // namespace linetrack

// Conversion of raw camera buffers (mono, Bayer mosaics, packed RGB/BGR; 8 bits or 10 to 16 bits
// in little-endian 16-bit containers) to the 8-bit grey images linetrack works on.
#pragma once

#include <visp3/core/vpImage.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace linetrack {

// Layout of the samples. Bayer patterns are named by their top-left 2x2 cell read row by row,
// as GenICam (PFNC) and Aravis name them: BayerRG = R G / G B.
enum class PixelKind { kMono, kBayerRG, kBayerGR, kBayerGB, kBayerBG, kRgb, kBgr };

// A device pixel format: layout and significant bits per sample (8 = one byte per sample;
// 10..16 = two bytes per sample, little endian, value in the low bits).
struct PixelFormat {
  PixelKind kind = PixelKind::kMono;
  int bits = 8;

  int BytesPerPixel() const;  // 1 or 2 for mono and Bayer, 3 for RGB/BGR (8-bit only)
  bool IsValid() const;       // bits in 8..16, and RGB/BGR only with 8 bits
  std::string Name() const;   // GenICam-style name: "Mono8", "BayerRG12", "RGB8", ...
};

// Parses a GenICam pixel format name ("Mono8", "Mono12", "BayerGR8", "RGB8", "BGR8", ...).
// Returns false for formats linetrack cannot convert (packed 10/12-bit, YUV, ...).
bool ParsePixelFormatName(const std::string& name, PixelFormat* format);

// A view on a raw buffer owned by someone else.
struct RawImage {
  PixelFormat format;
  int width = 0;
  int height = 0;
  std::size_t stride_bytes = 0;  // bytes from one row to the next (>= width * bytes per pixel)
  const std::uint8_t* data = nullptr;
  std::size_t size_bytes = 0;  // bytes available at data (checked against stride * height)
};

// Converts `raw` to 8-bit grey in *grey (resized only when the size changes). Mono: the top 8 of
// the significant bits. Colour: Y = 0.299 R + 0.587 G + 0.114 B (ITU-R BT.601, as OpenCV);
// Bayer: bilinear demosaicing folded into the grey conversion (OpenCV). Returns false with
// *why set when the buffer is too small or the format invalid.
bool ConvertToGrey(const RawImage& raw, vpImage<unsigned char>* grey, std::string* why);

}  // namespace linetrack

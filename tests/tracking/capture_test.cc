// Frame sources without a camera: frame-id arithmetic, spec strings, pixel conversion against
// exact mosaics and ViSP's Bayer images of Klimt, image sequences starting at 0, 1 and 7, the
// MPEG-1 trap, and the V4L2 "no such device" path.
#include <gtest/gtest.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/io/vpImageIo.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

#include "models/errors.h"
#include "tracking/capture/pixel_convert.h"
#include "tracking/capture/source_factory.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

constexpr double kGreyTol = 1.0;           // grey levels: rounding of the BT.601 weights
constexpr double kBayerMeanAbsTol = 14.0;  // grey levels: bilinear demosaicing of a detailed
                                           // painting (11 here; a wrong pattern gives >= 25)
constexpr std::uint64_t kGigEWrap = 65535;

std::string VispImages() {
  const char* env = std::getenv("VISP_INPUT_IMAGE_PATH");
  return std::string(env ? env : "/usr/share/visp-images-data") + "/ViSP-images";
}

double ExpectedGrey(double r, double g, double b) {
  return 0.299 * r + 0.587 * g + 0.114 * b;
}

TEST(FrameIdGap, CountsMissingIdsOnTheGigERing) {
  EXPECT_EQ(FrameIdGap(10, 11, kGigEWrap), 0);
  EXPECT_EQ(FrameIdGap(10, 13, kGigEWrap), 2);
  EXPECT_EQ(FrameIdGap(65535, 1, kGigEWrap), 0);  // the id after 65535 is 1, never 0
  EXPECT_EQ(FrameIdGap(65534, 2, kGigEWrap), 2);  // 65535 and 1 missing
  EXPECT_EQ(FrameIdGap(65535, 0, kGigEWrap), -1);
  EXPECT_EQ(FrameIdGap(100, 50, kGigEWrap), -1);  // restart
  EXPECT_EQ(FrameIdGap(7, 7, kGigEWrap), -1);
}

TEST(FrameIdGap, SixtyFourBitIdsDoNotWrap) {
  EXPECT_EQ(FrameIdGap(5, 6, 0), 0);
  EXPECT_EQ(FrameIdGap(1ull << 40, (1ull << 40) + 3, 0), 2);
  EXPECT_EQ(FrameIdGap(5, 5, 0), -1);
  EXPECT_EQ(FrameIdGap(65535, 1, 0), -1);
}

TEST(SourceSpec, ParsesEveryKind) {
  EXPECT_EQ(ParseSourceSpec("aravis").kind, SourceKind::kAravis);
  EXPECT_EQ(ParseSourceSpec("aravis").argument, "");
  EXPECT_EQ(ParseSourceSpec("aravis:00:0c:df:04:a1:b2").argument, "00:0c:df:04:a1:b2");
  EXPECT_EQ(ParseSourceSpec("v4l2").argument, "/dev/video0");
  EXPECT_EQ(ParseSourceSpec("v4l2:/dev/video3").kind, SourceKind::kV4l2);
  EXPECT_EQ(ParseSourceSpec("v4l2:/dev/video3").argument, "/dev/video3");
  EXPECT_EQ(ParseSourceSpec("sim").kind, SourceKind::kSim);
  EXPECT_EQ(ParseSourceSpec("sim:hall").argument, "hall");
  EXPECT_EQ(ParseSourceSpec("file:aravis.avi").kind, SourceKind::kVideo);
  EXPECT_EQ(ParseSourceSpec("file:aravis.avi").argument, "aravis.avi");
  EXPECT_EQ(ParseSourceSpec("/data/run/f_%05d.png").kind, SourceKind::kVideo);
  EXPECT_EQ(ParseSourceSpec("aravisfile.avi").kind, SourceKind::kVideo);
  EXPECT_THROW(ParseSourceSpec(""), InputError);
  EXPECT_THROW(ParseSourceSpec("file:"), InputError);
}

// A one-frame source standing in for the renderer.
class ConstantSource : public FrameSource {
 public:
  explicit ConstantSource(std::string args) : args_(std::move(args)) {}
  FrameStatus Grab(Frame* frame) override {
    frame->image.resize(2, 3, 7);
    return FrameStatus::kOk;
  }
  std::string Describe() const override { return "sim:" + args_; }
  SourceStats Stats() const override { return {}; }

 private:
  std::string args_;
};

TEST(SourceFactory, SimNeedsAMaker) {
  FrameSourceOptions options;
  try {
    OpenFrameSource("sim", options);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("simulated camera"), std::string::npos) << e.what();
  }
  options.make_sim = [](const std::string& args) { return std::make_unique<ConstantSource>(args); };
  const auto source = OpenFrameSource("sim:hall,seed=3", options);
  EXPECT_EQ(source->Describe(), "sim:hall,seed=3");
}

TEST(PixelFormat, ParsesGenICamNames) {
  PixelFormat f;
  ASSERT_TRUE(ParsePixelFormatName("Mono8", &f));
  EXPECT_EQ(f.kind, PixelKind::kMono);
  EXPECT_EQ(f.bits, 8);
  ASSERT_TRUE(ParsePixelFormatName("Mono12", &f));
  EXPECT_EQ(f.bits, 12);
  EXPECT_EQ(f.BytesPerPixel(), 2);
  ASSERT_TRUE(ParsePixelFormatName("BayerGB8", &f));
  EXPECT_EQ(f.kind, PixelKind::kBayerGB);
  ASSERT_TRUE(ParsePixelFormatName("RGB8", &f));
  EXPECT_EQ(f.BytesPerPixel(), 3);
  EXPECT_EQ(f.Name(), "RGB8");
  for (const char* bad : {"Mono12Packed", "RGB10", "YUV422_8", "Mono", "Mono8Signed", "Mono32"}) {
    EXPECT_FALSE(ParsePixelFormatName(bad, &f)) << bad;
  }
}

TEST(ConvertToGrey, Mono8HonoursTheRowStride) {
  const int w = 5, h = 3, stride = 8;
  std::vector<std::uint8_t> data(stride * h, 0xEE);  // 0xEE fills the padding
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      data[y * stride + x] = static_cast<std::uint8_t>(10 * y + x);
  RawImage raw{{PixelKind::kMono, 8}, w, h, stride, data.data(), data.size()};
  vpImage<unsigned char> grey;
  std::string why;
  ASSERT_TRUE(ConvertToGrey(raw, &grey, &why)) << why;
  ASSERT_EQ(grey.getWidth(), 5u);
  ASSERT_EQ(grey.getHeight(), 3u);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      EXPECT_EQ(grey[y][x], 10 * y + x);
}

TEST(ConvertToGrey, Mono12KeepsTheTopEightBits) {
  const std::vector<std::uint16_t> values = {0x0ABC, 0x0FFF, 0x0000, 0x0010};
  std::vector<std::uint8_t> data;
  for (std::uint16_t v : values) {
    data.push_back(static_cast<std::uint8_t>(v & 0xFF));  // little endian
    data.push_back(static_cast<std::uint8_t>(v >> 8));
  }
  RawImage raw{{PixelKind::kMono, 12}, 4, 1, 8, data.data(), data.size()};
  vpImage<unsigned char> grey;
  std::string why;
  ASSERT_TRUE(ConvertToGrey(raw, &grey, &why)) << why;
  EXPECT_EQ(grey[0][0], 0xAB);
  EXPECT_EQ(grey[0][1], 0xFF);
  EXPECT_EQ(grey[0][2], 0x00);
  EXPECT_EQ(grey[0][3], 0x01);
}

TEST(ConvertToGrey, RgbAndBgrGiveBt601Luma) {
  const double r = 200, g = 100, b = 50;
  for (PixelKind kind : {PixelKind::kRgb, PixelKind::kBgr}) {
    std::vector<std::uint8_t> data;
    for (int i = 0; i < 6; ++i) {
      data.push_back(static_cast<std::uint8_t>(kind == PixelKind::kRgb ? r : b));
      data.push_back(static_cast<std::uint8_t>(g));
      data.push_back(static_cast<std::uint8_t>(kind == PixelKind::kRgb ? b : r));
    }
    RawImage raw{{kind, 8}, 3, 2, 9, data.data(), data.size()};
    vpImage<unsigned char> grey;
    std::string why;
    ASSERT_TRUE(ConvertToGrey(raw, &grey, &why)) << why;
    EXPECT_NEAR(grey[1][2], ExpectedGrey(r, g, b), kGreyTol);
  }
}

// Colour at (x, y) of a GenICam-named 2x2 pattern ("RGGB" = R G / G B), as 0 = R, 1 = G, 2 = B.
int BayerChannel(const std::string& cell, int x, int y) {
  const char c = cell[2 * (y % 2) + (x % 2)];
  return c == 'R' ? 0 : (c == 'G' ? 1 : 2);
}

TEST(ConvertToGrey, BayerPatternsFollowGenICamNaming) {
  const double rgb[3] = {250, 120, 10};  // R and B far apart: a swapped pattern is 44 levels off
  const struct {
    PixelKind kind;
    const char* cell;
  } kPatterns[] = {{PixelKind::kBayerRG, "RGGB"},
                   {PixelKind::kBayerGR, "GRBG"},
                   {PixelKind::kBayerGB, "GBRG"},
                   {PixelKind::kBayerBG, "BGGR"}};
  const int w = 16, h = 12;
  for (const auto& p : kPatterns) {
    for (int bits : {8, 12}) {
      std::vector<std::uint8_t> data;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const int value = static_cast<int>(rgb[BayerChannel(p.cell, x, y)]) << (bits - 8);
          data.push_back(static_cast<std::uint8_t>(value & 0xFF));
          if (bits > 8) data.push_back(static_cast<std::uint8_t>(value >> 8));
        }
      PixelFormat format{p.kind, bits};
      RawImage raw{format,      w,          h, static_cast<std::size_t>(w * format.BytesPerPixel()),
                   data.data(), data.size()};
      vpImage<unsigned char> grey;
      std::string why;
      ASSERT_TRUE(ConvertToGrey(raw, &grey, &why)) << why;
      for (int y = 2; y < h - 2; ++y)
        for (int x = 2; x < w - 2; ++x)
          ASSERT_NEAR(grey[y][x], ExpectedGrey(rgb[0], rgb[1], rgb[2]), kGreyTol)
              << format.Name() << " at " << x << "," << y;
    }
  }
}

TEST(ConvertToGrey, KlimtBayerImagesMatchTheColourOriginal) {
  const std::string dir = VispImages();
  vpImage<vpRGBa> colour;
  vpImageIo::read(colour, dir + "/Klimt/Klimt.ppm");
  const int w = 558, h = 560;  // the files are named 560x558 (rows x columns)
  ASSERT_EQ(colour.getWidth(), static_cast<unsigned>(w));
  ASSERT_EQ(colour.getHeight(), static_cast<unsigned>(h));
  std::vector<std::uint8_t> rgb;
  for (unsigned i = 0; i < colour.getSize(); ++i) {
    rgb.insert(rgb.end(), {colour.bitmap[i].R, colour.bitmap[i].G, colour.bitmap[i].B});
  }
  vpImage<unsigned char> reference;
  std::string why;
  ASSERT_TRUE(ConvertToGrey(
      {{PixelKind::kRgb, 8}, w, h, static_cast<std::size_t>(3 * w), rgb.data(), rgb.size()},
      &reference, &why))
      << why;
  const struct {
    PixelKind kind;
    const char* name;
  } kFiles[] = {{PixelKind::kBayerRG, "RGGB"},
                {PixelKind::kBayerGR, "GRBG"},
                {PixelKind::kBayerGB, "GBRG"},
                {PixelKind::kBayerBG, "BGGR"}};
  for (const auto& f : kFiles) {
    for (int bits : {8, 12}) {
      const std::string path = dir + "/Bayer/Klimt_Bayer_560x558_" + f.name + "_" +
                               (bits == 8 ? "08" : "12") + "bits.raw";
      std::ifstream in(path, std::ios::binary);
      ASSERT_TRUE(in) << path;
      const std::vector<std::uint8_t> column_major((std::istreambuf_iterator<char>(in)),
                                                   std::istreambuf_iterator<char>());
      const int bpp = bits > 8 ? 2 : 1;
      ASSERT_EQ(column_major.size(), static_cast<std::size_t>(w * h * bpp)) << path;
      // ViSP stores these mosaics column by column (its tests' col2im): make rows.
      std::vector<std::uint8_t> raw_bytes(column_major.size());
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int b = 0; b < bpp; ++b)
            raw_bytes[(y * w + x) * bpp + b] = column_major[(x * h + y) * bpp + b];
      // Decode the mosaic as each of the four patterns: the named one must fit best.
      double named_error = 0.0, best_other = 1e9;
      for (const auto& as : kFiles) {
        vpImage<unsigned char> grey;
        ASSERT_TRUE(ConvertToGrey({{as.kind, bits},
                                   w,
                                   h,
                                   static_cast<std::size_t>(w * bpp),
                                   raw_bytes.data(),
                                   raw_bytes.size()},
                                  &grey, &why))
            << why;
        double sum = 0.0;
        int n = 0;
        for (int y = 2; y < h - 2; ++y)
          for (int x = 2; x < w - 2; ++x, ++n)
            sum += std::abs(grey[y][x] - reference[y][x]);
        if (as.kind == f.kind) {
          named_error = sum / n;
        } else {
          best_other = std::min(best_other, sum / n);
        }
      }
      EXPECT_LT(named_error, kBayerMeanAbsTol) << path;
      EXPECT_LT(named_error, best_other) << path;
    }
  }
}

TEST(ConvertToGrey, RefusesShortBuffers) {
  std::vector<std::uint8_t> data(10);
  vpImage<unsigned char> grey;
  std::string why;
  EXPECT_FALSE(
      ConvertToGrey({{PixelKind::kMono, 8}, 4, 4, 4, data.data(), data.size()}, &grey, &why));
  EXPECT_NE(why.find("needs 16"), std::string::npos) << why;
  EXPECT_FALSE(
      ConvertToGrey({{PixelKind::kRgb, 12}, 2, 2, 6, data.data(), data.size()}, &grey, &why));
}

}  // namespace
}  // namespace linetrack

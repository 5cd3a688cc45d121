// The replay reader on ViSP's sample sequences (numbered from 0 and from 1), on a sequence
// written here from 7, on the raw MPEG-1 video, and the V4L2 "no such device" path.
#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/io/vpImageIo.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "models/errors.h"
#include "tracking/capture/source_factory.h"

namespace linetrack {
namespace {

namespace fs = std::filesystem;

constexpr double kTimeTolS = 1e-9;

std::string VispImages() {
  const char* env = std::getenv("VISP_INPUT_IMAGE_PATH");
  return std::string(env ? env : "/usr/share/visp-images-data") + "/ViSP-images";
}

bool SameImage(const vpImage<unsigned char>& a, const vpImage<unsigned char>& b) {
  return a.getWidth() == b.getWidth() && a.getHeight() == b.getHeight() &&
         std::equal(a.bitmap, a.bitmap + a.getSize(), b.bitmap);
}

// A scratch folder removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    path_ = fs::temp_directory_path() /
            ("linetrack_video_" + std::to_string(getpid()) + "_" + std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string str() const { return path_.string(); }

 private:
  static inline int counter_ = 0;
  fs::path path_;
};

TEST(SequencePattern, SplitsAndFormats) {
  SequencePattern p;
  ASSERT_TRUE(ParseSequencePattern("/data/run 1/frame_%05d.png", &p));
  EXPECT_EQ(p.directory, "/data/run 1");
  EXPECT_EQ(p.prefix, "frame_");
  EXPECT_EQ(p.suffix, ".png");
  EXPECT_EQ(SequenceFileName(p, 42), "frame_00042.png");
  EXPECT_EQ(SequenceFileName(p, 1234567), "frame_1234567.png");
  ASSERT_TRUE(ParseSequencePattern("img%d.pgm", &p));
  EXPECT_EQ(p.directory, ".");
  EXPECT_EQ(SequenceFileName(p, 7), "img7.pgm");
  EXPECT_FALSE(ParseSequencePattern("/data/frame.png", &p));
  EXPECT_FALSE(ParseSequencePattern("/data/%d/frame.png", &p));
  EXPECT_FALSE(ParseSequencePattern("/data/f_%d_%d.png", &p));
  EXPECT_FALSE(ParseSequencePattern("/data/f_%s.png", &p));
}

TEST(SequencePattern, FindsTheFirstRunOfNumbers) {
  TempDir dir;
  for (int i : {3, 4, 5, 6, 7, 9}) {
    std::ofstream(dir.str() + "/frame_" + std::string(i < 10 ? "0000" : "000") + std::to_string(i) +
                  ".png")
        << "x";
  }
  std::ofstream(dir.str() + "/frame_2.png") << "x";      // wrong width: not frame 2
  std::ofstream(dir.str() + "/frame_00001.jpg") << "x";  // wrong suffix
  SequencePattern p;
  ASSERT_TRUE(ParseSequencePattern(dir.str() + "/frame_%05d.png", &p));
  long first = 0, last = 0;
  ASSERT_TRUE(FindSequenceRange(p, &first, &last));
  EXPECT_EQ(first, 3);
  EXPECT_EQ(last, 7);
}

TEST(VideoSource, ReadsTheCubeSequenceFromZero) {
  const std::string pattern = VispImages() + "/mbt/cube/image%04d.pgm";
  VideoSource source(pattern, VideoSourceOptions{});
  EXPECT_EQ(source.FrameCount(), 218);
  Frame frame;
  vpImage<unsigned char> expected;
  long n = 0;
  FrameStatus status;
  while ((status = source.Grab(&frame)) == FrameStatus::kOk) {
    ASSERT_EQ(frame.frame_id, static_cast<std::uint64_t>(n));
    ASSERT_EQ(frame.index, n);
    ASSERT_NEAR(frame.timestamp_s, n / 30.0, kTimeTolS);
    if (n == 0 || n == 217) {
      char name[32];
      std::snprintf(name, sizeof(name), "/image%04ld.pgm", n);
      vpImageIo::read(expected, VispImages() + "/mbt/cube" + name);
      EXPECT_TRUE(SameImage(frame.image, expected)) << "frame " << n;
    }
    ++n;
  }
  EXPECT_EQ(status, FrameStatus::kEndOfStream);
  EXPECT_EQ(n, 218);
  EXPECT_EQ(source.Grab(&frame), FrameStatus::kEndOfStream);  // stays at the end
}

TEST(VideoSource, ReadsTheCastleSequenceFromOne) {
  const std::string dir = VispImages() + "/mbt-depth/Castle-simu/Images";
  VideoSourceOptions options;
  options.frame_rate = 10.0;
  VideoSource source(dir + "/Image_%04d.pgm", options);
  EXPECT_EQ(source.FrameCount(), 40);
  Frame frame;
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk);
  EXPECT_EQ(frame.frame_id, 1u);
  vpImage<unsigned char> expected;
  vpImageIo::read(expected, dir + "/Image_0001.pgm");
  EXPECT_TRUE(SameImage(frame.image, expected));
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk);
  EXPECT_EQ(frame.frame_id, 2u);
  EXPECT_NEAR(frame.timestamp_s, 0.1, kTimeTolS);
}

TEST(VideoSource, SequenceFromSevenWithARange) {
  TempDir dir;
  vpImage<unsigned char> image;
  for (int i = 0; i < 5; ++i) {
    char src[64], dst[64];
    std::snprintf(src, sizeof(src), "/mbt/cube/image%04d.pgm", i);
    std::snprintf(dst, sizeof(dst), "/f_%03d.png", 7 + i);
    vpImageIo::read(image, VispImages() + src);
    vpImageIo::write(image, dir.str() + dst);
  }
  VideoSource all(dir.str() + "/f_%03d.png", VideoSourceOptions{});
  EXPECT_EQ(all.FrameCount(), 5);
  Frame frame;
  ASSERT_EQ(all.Grab(&frame), FrameStatus::kOk);
  EXPECT_EQ(frame.frame_id, 7u);
  vpImageIo::read(image, VispImages() + "/mbt/cube/image0000.pgm");
  EXPECT_TRUE(SameImage(frame.image, image));  // PNG is lossless

  VideoSourceOptions options;
  options.first_index = 9;
  options.last_index = 10;
  VideoSource part(dir.str() + "/f_%03d.png", options);
  std::vector<std::uint64_t> ids;
  while (part.Grab(&frame) == FrameStatus::kOk)
    ids.push_back(frame.frame_id);
  EXPECT_EQ(ids, (std::vector<std::uint64_t>{9, 10}));

  options.last_index = 12;  // frame 12 does not exist
  EXPECT_THROW(VideoSource(dir.str() + "/f_%03d.png", options), InputError);
}

TEST(VideoSource, RawMpegIsReadToItsRealEnd) {
  // The container reports one frame; reading sequentially must deliver them all and then stop.
  VideoSource source(VispImages() + "/video/cube.mpeg", VideoSourceOptions{});
  Frame frame;
  long n = 0;
  FrameStatus status = FrameStatus::kOk;
  for (int guard = 0; guard < 100000 && status == FrameStatus::kOk; ++guard) {
    status = source.Grab(&frame);
    if (status == FrameStatus::kOk) {
      ASSERT_EQ(frame.image.getWidth(), 384u);
      ASSERT_EQ(frame.image.getHeight(), 288u);
      ++n;
    }
  }
  EXPECT_EQ(status, FrameStatus::kEndOfStream);
  EXPECT_GT(n, 1);
  EXPECT_NEAR(frame.timestamp_s, (n - 1) / 25.0, kTimeTolS);  // the file's 25 fps
}

TEST(VideoSource, SingleImageIsOneFrame) {
  VideoSource source(VispImages() + "/Klimt/Klimt.ppm", VideoSourceOptions{});
  Frame frame;
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk);
  EXPECT_EQ(frame.image.getWidth(), 558u);
  EXPECT_EQ(source.Grab(&frame), FrameStatus::kEndOfStream);
}

void ExpectInputError(const std::string& spec, const std::string& fragment) {
  try {
    OpenFrameSource(spec, FrameSourceOptions{});
    ADD_FAILURE() << spec << ": expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(VideoSource, ClearErrorsForMissingInput) {
  TempDir dir;
  ExpectInputError(dir.str() + "/none.avi", "no such file");
  ExpectInputError(dir.str() + "/f_%04d.png", "no file matches");
  ExpectInputError(dir.str() + "/missing/f_%04d.png", "no such directory");
}

TEST(V4l2Source, NoSuchDeviceIsAClearError) {
  ExpectInputError("v4l2:/dev/video-linetrack-none", "no such device");
  ExpectInputError("v4l2:/dev/null", "v4l2:/dev/null");  // a character device, but not V4L2
}

}  // namespace
}  // namespace linetrack

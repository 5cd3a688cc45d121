// The Aravis source for real: Aravis' in-process "Fake" camera for format conversion, and the
// fake GigE Vision camera (arv-fake-gv-camera-0.8, a child process on 127.0.0.1) for the
// protocol, frame ids through their wrap, timestamps, and recovery after the camera is killed and
// restarted. Ground truth: a Mono8 fake frame with id k holds I(x, y) = (x + y + k) mod 255.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "models/errors.h"
#include "tracking/capture/aravis_source.h"
#include "tracking/fake_gige/fake_gige_camera.h"

namespace linetrack {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint64_t kGigEWrap = 65535;
// Bounds on waits, so that a broken source fails the test instead of hanging it. They are not
// performance thresholds: a healthy run stays far below them.
constexpr double kStreamDeadlineS = 20.0;
constexpr double kLossDeadlineS = 10.0;
constexpr double kRecoveryDeadlineS = 40.0;

double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// True when the image is the fake camera's diagonal ramp for frame id `id`.
// The fake's ramp value at (x, y) for frame `id`, as 8-bit grey: (x + y + id) mod 255 in Mono8;
// Mono16 holds 256 (x + y + id) mod 65535, of which the grey image keeps the top byte.
unsigned RampValue(unsigned x, unsigned y, std::uint64_t id, int bits) {
  if (bits == 16) return static_cast<unsigned>(((256 * (x + y + id)) % 65535) >> 8);
  return static_cast<unsigned>((x + y + id) % 255);
}

bool IsRampOfId(const vpImage<unsigned char>& image, std::uint64_t id, std::string* where,
                int bits = 8) {
  for (unsigned y = 0; y < image.getHeight(); ++y)
    for (unsigned x = 0; x < image.getWidth(); ++x) {
      const unsigned expected = RampValue(x, y, id, bits);
      if (image[y][x] != expected) {
        *where = "pixel (" + std::to_string(x) + "," + std::to_string(y) + ") is " +
                 std::to_string(image[y][x]) + ", expected " + std::to_string(expected);
        return false;
      }
    }
  return true;
}

AravisSourceOptions InProcessFake(const std::string& pixel_format) {
  AravisSourceOptions options;
  options.device_id = "Fake_1";
  options.pixel_format = pixel_format;
  options.width = 320;
  options.height = 240;
  options.frame_rate = 100.0;
  return options;
}

TEST(AravisFake, Mono8IsTheRampOfItsFrameId) {
  AravisSource source(InProcessFake("Mono8"));
  EXPECT_EQ(source.FrameIdWrap(), kGigEWrap);
  Frame frame;
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk) << source.LastError();
    ASSERT_EQ(frame.image.getWidth(), 320u);
    ASSERT_EQ(frame.image.getHeight(), 240u);
    ASSERT_NE(frame.frame_id, 0u);
    std::string where;
    EXPECT_TRUE(IsRampOfId(frame.image, frame.frame_id, &where)) << where;
    EXPECT_TRUE(frame.has_camera_timestamp);
  }
}

TEST(AravisFake, Mono16KeepsTheTopByte) {
  AravisSource source(InProcessFake("Mono16"));
  Frame frame;
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk) << source.LastError();
  std::string where;
  EXPECT_TRUE(IsRampOfId(frame.image, frame.frame_id, &where, 16)) << where;
}

TEST(AravisFake, Rgb8GreyDependsOnlyOnTheRampValue) {
  // The fake colours the ramp with a colour map: grey must be a function of (x + y + id) mod 255,
  // the same in every frame. A wrong stride or channel order breaks this.
  AravisSource source(InProcessFake("RGB8"));
  std::vector<int> grey_of_ramp(255, -1);
  Frame frame;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk) << source.LastError();
    for (unsigned y = 0; y < frame.image.getHeight(); ++y)
      for (unsigned x = 0; x < frame.image.getWidth(); ++x) {
        int& expected = grey_of_ramp[(x + y + frame.frame_id) % 255];
        if (expected < 0) expected = frame.image[y][x];
        ASSERT_EQ(frame.image[y][x], expected) << "at " << x << "," << y;
      }
  }
  const auto [lo, hi] = std::minmax_element(grey_of_ramp.begin(), grey_of_ramp.end());
  EXPECT_GT(*hi - *lo, 50);  // a real colour map, not a constant image
}

TEST(AravisFake, LatestOnlyDeliversTheNewestWaitingFrame) {
  AravisSourceOptions options = InProcessFake("Mono8");
  options.latest_only = true;
  AravisSource source(options);
  Frame frame;
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk) << source.LastError();
  const std::uint64_t first_id = frame.frame_id;
  // A consumer slower than the camera: frames pile up in the stream's output queue.
  constexpr int kBacklog = 3;
  const Clock::time_point start = Clock::now();
  while (source.WaitingFrames() < kBacklog)
    ASSERT_LT(SecondsSince(start), kStreamDeadlineS) << "no backlog of frames formed";
  ASSERT_EQ(source.Grab(&frame), FrameStatus::kOk) << source.LastError();
  std::string where;
  EXPECT_TRUE(IsRampOfId(frame.image, frame.frame_id, &where)) << where;
  const SourceStats stats = source.Stats();
  EXPECT_GE(stats.skipped, kBacklog - 1);
  EXPECT_EQ(stats.delivered, 2);
  // Every frame between the two deliveries was either passed over or lost on the way.
  EXPECT_EQ(FrameIdGap(first_id, frame.frame_id, kGigEWrap), stats.skipped + stats.missed);
}

void ExpectOpenError(const AravisSourceOptions& options, const std::string& fragment) {
  try {
    AravisSource source(options);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(AravisFake, BadSettingsAreClearErrors) {
  AravisSourceOptions options = InProcessFake("YUV422Packed");
  ExpectOpenError(options, "PixelFormat YUV422Packed");
  options = InProcessFake("Mono8");
  options.frame_rate = 5000.0;
  ExpectOpenError(options, "frame rate 5000 outside the camera's range");
  options = InProcessFake("Mono8");
  options.n_buffers = 1;
  ExpectOpenError(options, "number of buffers");
  options.n_buffers = 8;
  options.device_id = "Fake_no_such_camera";
  ExpectOpenError(options, "'Fake_no_such_camera' not found");
}

// A fake GigE camera per test, killed in teardown.
class AravisGigE : public ::testing::Test {
 protected:
  void SetUp() override {
    FakeGigECameraOptions options;
    options.serial = "LTTEST" + std::to_string(getpid());
    camera_ = std::make_unique<FakeGigECamera>(options);
    std::string why;
    ASSERT_TRUE(camera_->Start(&why)) << why;
  }
  void TearDown() override { camera_.reset(); }

  AravisSourceOptions Options(double frame_rate) const {
    AravisSourceOptions options;
    options.device_id = camera_->options().serial;
    options.pixel_format = "Mono8";
    options.width = 640;
    options.height = 480;
    options.frame_rate = frame_rate;
    options.grab_timeout_s = 0.2;
    options.loss_timeout_s = 0.5;
    options.reconnect_backoff_s = 0.1;
    options.reconnect_backoff_max_s = 0.5;
    return options;
  }

  std::unique_ptr<FakeGigECamera> camera_;
};

// Checks a run of frames: content matches the id, ids never 0 and never going back, camera
// timestamps increasing. Returns the number of missed ids, and whether the wrap was crossed.
struct RunCheck {
  std::int64_t frames = 0, missed = 0;
  bool wrapped = false;
  bool saw_65535_then_1 = false;
};

void CheckFrame(const Frame& frame, const Frame* previous, RunCheck* run) {
  ASSERT_EQ(frame.image.getWidth(), 640u);
  ASSERT_EQ(frame.image.getHeight(), 480u);
  ASSERT_NE(frame.frame_id, 0u);
  ASSERT_LE(frame.frame_id, kGigEWrap);
  std::string where;
  ASSERT_TRUE(IsRampOfId(frame.image, frame.frame_id, &where))
      << "frame " << frame.frame_id << ": " << where;
  ASSERT_TRUE(frame.has_camera_timestamp);
  if (previous != nullptr) {
    const std::int64_t gap = FrameIdGap(previous->frame_id, frame.frame_id, kGigEWrap);
    ASSERT_GE(gap, 0) << previous->frame_id << " -> " << frame.frame_id;
    ASSERT_GT(frame.timestamp_s, previous->timestamp_s);
    run->missed += gap;
    if (frame.frame_id < previous->frame_id) run->wrapped = true;
    if (previous->frame_id == kGigEWrap && frame.frame_id == 1) run->saw_65535_then_1 = true;
  }
  ++run->frames;
}

TEST_F(AravisGigE, StreamsThroughTheFrameIdWrap) {
  const std::vector<AravisDeviceInfo> devices = ListAravisDevices();
  const auto found = std::find_if(devices.begin(), devices.end(), [&](const AravisDeviceInfo& d) {
    return d.serial == camera_->options().serial;
  });
  ASSERT_NE(found, devices.end());
  EXPECT_EQ(found->protocol, "GigEVision");
  EXPECT_EQ(found->address, "127.0.0.1");
  EXPECT_EQ(found->model, "Fake");

  AravisSource source(Options(100.0));
  EXPECT_EQ(source.FrameIdWrap(), kGigEWrap);
  RunCheck run;
  Frame frame, previous;
  bool have_previous = false;
  std::int64_t after_wrap = 0;
  const auto start = Clock::now();
  while (after_wrap < 20 && SecondsSince(start) < kStreamDeadlineS) {
    const FrameStatus status = source.Grab(&frame);
    ASSERT_NE(status, FrameStatus::kDeviceLost) << source.LastError();
    if (status != FrameStatus::kOk) continue;
    CheckFrame(frame, have_previous ? &previous : nullptr, &run);
    if (HasFatalFailure()) return;
    if (run.wrapped) ++after_wrap;
    previous = frame;
    have_previous = true;
  }
  EXPECT_TRUE(run.wrapped) << "ids never wrapped in " << run.frames << " frames";
  // Loopback at 30 MB/s loses nothing (also under ASan with the machine loaded): the ids are
  // consecutive, and the wrap goes from 65535 straight to 1.
  EXPECT_EQ(run.missed, 0);
  EXPECT_TRUE(run.saw_65535_then_1);
  EXPECT_EQ(source.Stats().missed, run.missed);
  EXPECT_EQ(source.Stats().delivered, run.frames);
  EXPECT_EQ(frame.index, run.frames - 1);
}

TEST_F(AravisGigE, RecoversAfterTheCameraIsKilledAndRestarted) {
  const AravisSourceOptions options = Options(50.0);
  AravisSource source(options);
  Frame frame;
  int ok = 0;
  auto start = Clock::now();
  while (ok < 10 && SecondsSince(start) < kStreamDeadlineS) {
    if (source.Grab(&frame) == FrameStatus::kOk) ++ok;
  }
  ASSERT_EQ(ok, 10) << source.LastError();

  camera_->Kill();  // unplugged
  start = Clock::now();
  int calls = 0;
  FrameStatus status = FrameStatus::kOk;
  while (status != FrameStatus::kDeviceLost && SecondsSince(start) < kLossDeadlineS) {
    status = source.Grab(&frame);
    ++calls;
  }
  ASSERT_EQ(status, FrameStatus::kDeviceLost);
  // Frames still in flight, then timeouts until the loss timeout passes: a handful of calls.
  EXPECT_LE(calls, 2 + static_cast<int>(options.loss_timeout_s / options.grab_timeout_s) + 2);
  EXPECT_FALSE(source.LastError().empty());
  EXPECT_EQ(source.Grab(&frame), FrameStatus::kDeviceLost);  // still gone

  std::string why;
  ASSERT_TRUE(camera_->Start(&why)) << why;  // plugged back, same serial

  start = Clock::now();
  status = FrameStatus::kDeviceLost;
  while (status != FrameStatus::kOk && SecondsSince(start) < kRecoveryDeadlineS) {
    status = source.Grab(&frame);
  }
  ASSERT_EQ(status, FrameStatus::kOk) << source.LastError();

  RunCheck run;
  Frame previous = frame;
  CheckFrame(frame, nullptr, &run);
  start = Clock::now();
  while (run.frames < 20 && SecondsSince(start) < kStreamDeadlineS) {
    const FrameStatus next = source.Grab(&frame);
    ASSERT_NE(next, FrameStatus::kDeviceLost) << source.LastError();
    if (next != FrameStatus::kOk) continue;
    CheckFrame(frame, &previous, &run);
    if (HasFatalFailure()) return;
    previous = frame;
  }
  EXPECT_EQ(run.frames, 20);
  EXPECT_EQ(run.missed, 0);
  const SourceStats stats = source.Stats();
  EXPECT_EQ(stats.losses, 1);
  EXPECT_EQ(stats.reconnections, 1);
  EXPECT_GE(stats.reconnect_attempts, 1);
}

}  // namespace
}  // namespace linetrack

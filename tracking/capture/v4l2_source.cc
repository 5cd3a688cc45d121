#include "tracking/capture/v4l2_source.h"

#include <sys/stat.h>
#include <visp3/core/vpException.h>
#include <visp3/sensor/vpV4l2Grabber.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "models/errors.h"

namespace linetrack {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

bool V4l2SourceOptions::Check(std::string* why) const {
  if (input < 0) {
    *why = "input must be >= 0";
    return false;
  }
  if (scale != 1 && scale != 2 && scale != 4) {
    *why = "scale must be 1, 2 or 4";
    return false;
  }
  if (n_buffers < 1 || n_buffers > 32) {
    *why = "number of buffers must be in [1, 32]";
    return false;
  }
  if (!(reopen_backoff_s > 0.0)) {
    *why = "re-open backoff must be > 0 seconds";
    return false;
  }
  return true;
}

class V4l2Source::Impl {
 public:
  Impl(const std::string& device, const V4l2SourceOptions& options)
      : device_(device), options_(options) {
    std::string why;
    if (!options_.Check(&why)) throw InputError("v4l2:" + device + ": " + why);
    struct stat info {};
    if (stat(device.c_str(), &info) != 0) {
      throw InputError("v4l2:" + device + ": no such device (" + std::strerror(errno) + ")");
    }
    if (!S_ISCHR(info.st_mode)) {
      throw InputError("v4l2:" + device + ": not a character device");
    }
    if (!Open(&why)) throw InputError("v4l2:" + device + ": " + why);
  }

  FrameStatus Grab(Frame* frame) {
    if (!grabber_) {
      if (Clock::now() < next_attempt_) {
        std::this_thread::sleep_until(next_attempt_);
      }
      ++stats_.reconnect_attempts;
      std::string why;
      if (!Open(&why)) {
        last_error_ = "re-open failed: " + why;
        next_attempt_ = Clock::now() + std::chrono::milliseconds(
                                           static_cast<int>(1000 * options_.reopen_backoff_s));
        return FrameStatus::kDeviceLost;
      }
      ++stats_.reconnections;
    }
    struct timeval stamp {};
    try {
      grabber_->acquire(frame->image, stamp);
    } catch (const vpException& e) {
      last_error_ = e.getStringMessage();
      ++stats_.losses;
      grabber_.reset();
      next_attempt_ = Clock::now();
      return FrameStatus::kDeviceLost;
    }
    frame->timestamp_s = static_cast<double>(stamp.tv_sec) + 1e-6 * stamp.tv_usec;
    frame->has_camera_timestamp = false;  // driver time of capture, on the host clock
    frame->host_time_s =
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    frame->frame_id = static_cast<std::uint64_t>(stats_.delivered);
    frame->index = stats_.delivered++;
    return FrameStatus::kOk;
  }

  std::string Describe() const { return "v4l2:" + device_ + " (" + size_ + ")"; }
  SourceStats Stats() const { return stats_; }
  std::string LastError() const { return last_error_; }

 private:
  bool Open(std::string* why) {
    auto grabber = std::make_unique<vpV4l2Grabber>();
    try {
      grabber->setVerboseMode(false);
      grabber->setDevice(device_);
      grabber->setInput(static_cast<unsigned>(options_.input));
      grabber->setScale(static_cast<unsigned>(options_.scale));
      grabber->setNBuffers(static_cast<unsigned>(options_.n_buffers));
      vpImage<unsigned char> first;
      grabber->open(first);
      size_ = std::to_string(first.getWidth()) + "x" + std::to_string(first.getHeight());
    } catch (const vpException& e) {
      *why = e.getStringMessage();
      return false;
    }
    grabber_ = std::move(grabber);
    return true;
  }

  std::string device_;
  V4l2SourceOptions options_;
  std::unique_ptr<vpV4l2Grabber> grabber_;
  std::string size_ = "?";
  std::string last_error_;
  SourceStats stats_;
  Clock::time_point next_attempt_;
};

V4l2Source::V4l2Source(const std::string& device, const V4l2SourceOptions& options)
    : impl_(std::make_unique<Impl>(device, options)) {}
V4l2Source::~V4l2Source() = default;
FrameStatus V4l2Source::Grab(Frame* frame) {
  return impl_->Grab(frame);
}
std::string V4l2Source::Describe() const {
  return impl_->Describe();
}
SourceStats V4l2Source::Stats() const {
  return impl_->Stats();
}
std::string V4l2Source::LastError() const {
  return impl_->LastError();
}

}  // namespace linetrack

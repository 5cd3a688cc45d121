#include "tracking/capture/aravis_source.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>

#include "models/errors.h"
#include "tracking/capture/aravis_device.h"

namespace linetrack {
namespace {

using Clock = std::chrono::steady_clock;
using internal::AravisDevice;

Clock::duration Seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

double SecondsUntil(Clock::time_point t) {
  return std::chrono::duration<double>(t - Clock::now()).count();
}

// One background thread running posted tasks in order. Device teardown and re-opening run
// here: both can block for seconds on a dead GigE camera, and the order (release the old
// handle, then open a new one) matters for cameras that grant control to one host at a time.
// The destructor runs the remaining tasks, then joins.
class SerialWorker {
 public:
  SerialWorker() : thread_([this] { Run(); }) {}
  ~SerialWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  void Post(std::function<void()> task) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tasks_.push_back(std::move(task));
    }
    cv_.notify_all();
  }

 private:
  void Run() {
    for (;;) {
      std::function<void()> task;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stop_ || !tasks_.empty(); });
        if (tasks_.empty()) return;
        task = std::move(tasks_.front());
        tasks_.pop_front();
      }
      task();
    }
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> tasks_;
  bool stop_ = false;
  std::thread thread_;  // last: starts after the other members exist
};

struct OpenResult {
  std::unique_ptr<AravisDevice> device;
  std::string error;
};

}  // namespace

bool AravisSourceOptions::Check(std::string* why) const {
  auto fail = [why](const std::string& what) {
    *why = what;
    return false;
  };
  if (width < 0 || height < 0) return fail("width and height must be >= 0 (0 keeps the camera's)");
  if (!(frame_rate >= 0.0)) return fail("frame rate must be >= 0 (0 keeps the camera's)");
  if (!(exposure_us >= 0.0)) return fail("exposure must be >= 0 microseconds");
  if (std::isinf(gain)) return fail("gain must be finite (NaN keeps the camera's)");
  if (packet_size < -1) return fail("packet size must be > 0, 0 (keep) or -1 (negotiate)");
  if (n_buffers < 2 || n_buffers > 256) return fail("number of buffers must be in [2, 256]");
  if (!(grab_timeout_s > 0.0 && grab_timeout_s <= 60.0)) {
    return fail("grab timeout must be in (0, 60] seconds");
  }
  if (!(loss_timeout_s > 0.0 && loss_timeout_s <= 600.0)) {
    return fail("loss timeout must be in (0, 600] seconds");
  }
  if (frame_rate > 0.0 && loss_timeout_s < 2.0 / frame_rate) {
    return fail("loss timeout must cover at least two frame periods");
  }
  if (!(reconnect_backoff_s > 0.0) || !(reconnect_backoff_max_s >= reconnect_backoff_s)) {
    return fail("reconnect backoff must be > 0 and <= its maximum");
  }
  return true;
}

std::vector<AravisDeviceInfo> ListAravisDevices(bool include_fake) {
  if (include_fake) arv_enable_interface("Fake");
  arv_update_device_list();
  auto str = [](const char* s) { return std::string(s ? s : ""); };
  std::vector<AravisDeviceInfo> devices;
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    devices.push_back({str(arv_get_device_id(i)), str(arv_get_device_physical_id(i)),
                       str(arv_get_device_address(i)), str(arv_get_device_vendor(i)),
                       str(arv_get_device_model(i)), str(arv_get_device_serial_nbr(i)),
                       str(arv_get_device_protocol(i))});
  }
  return devices;
}

class AravisSource::Impl {
 public:
  explicit Impl(const AravisSourceOptions& options) : options_(options) {
    std::string why;
    if (!options_.Check(&why)) throw InputError("aravis source: " + why);
    device_ = AravisDevice::Open(options_, &why);
    const std::string name = options_.device_id.empty() ? "aravis" : "aravis:" + options_.device_id;
    if (!device_) throw InputError(name + ": " + why);
    description_ = device_->description();
    frame_id_wrap_ = device_->frame_id_wrap();
    last_frame_time_ = Clock::now();
  }

  ~Impl() {
    if (device_) Retire(std::move(device_), /*dead=*/false);
    // worker_'s destructor finishes the teardown and any pending open before returning.
  }

  FrameStatus Grab(Frame* frame) {
    const Clock::time_point deadline = Clock::now() + Seconds(options_.grab_timeout_s);
    if (!device_ && !TryRecover(deadline)) return FrameStatus::kDeviceLost;
    for (;;) {
      ArvBuffer* buffer = device_->Pop(std::max(0.001, SecondsUntil(deadline)));
      if (buffer != nullptr && options_.latest_only) buffer = NewestWaiting(buffer);
      if (buffer != nullptr) {
        if (arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS) {
          std::string why;
          const bool converted = device_->ToFrame(buffer, frame, &why);
          device_->Push(buffer);
          if (converted) {
            Delivered(frame);
            return FrameStatus::kOk;
          }
          last_error_ = "frame dropped: " + why;
        } else {
          device_->Push(buffer);
        }
        ++stats_.incomplete;
      }
      const Clock::time_point now = Clock::now();
      if (device_->ControlLost()) return Lose("camera control lost (heartbeat failed)");
      if (now - last_frame_time_ > Seconds(options_.loss_timeout_s)) {
        return Lose("no complete frame for " + std::to_string(options_.loss_timeout_s) + " s");
      }
      if (now >= deadline) {
        ++stats_.timeouts;
        return FrameStatus::kTimeout;
      }
    }
  }

  std::string Describe() const { return description_; }
  std::string LastError() const { return last_error_; }
  std::uint64_t FrameIdWrap() const { return frame_id_wrap_; }
  int WaitingFrames() const { return device_ ? device_->WaitingBuffers() : 0; }

  SourceStats Stats() const {
    SourceStats stats = stats_;
    if (device_) {
      std::uint64_t completed = 0, failures = 0, underruns = 0;
      device_->StreamStatistics(&completed, &failures, &underruns);
      stats.underruns += static_cast<std::int64_t>(underruns);
    }
    return stats;
  }

 private:
  // `buffer` or, when newer complete buffers already wait behind it, the newest of them; the
  // buffers passed over go back to the pool and count as skipped.
  ArvBuffer* NewestWaiting(ArvBuffer* buffer) {
    while (ArvBuffer* newer = device_->TryPop()) {
      if (arv_buffer_get_status(newer) != ARV_BUFFER_STATUS_SUCCESS) {
        device_->Push(newer);
        ++stats_.incomplete;
        continue;
      }
      if (arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS) {
        Seen(arv_buffer_get_frame_id(buffer));
        ++stats_.skipped;
      } else {
        ++stats_.incomplete;
      }
      device_->Push(buffer);
      buffer = newer;
    }
    return buffer;
  }

  // Accounts for a frame id received (delivered or skipped): gaps before it were missed.
  void Seen(std::uint64_t frame_id) {
    if (have_previous_id_) {
      const std::int64_t gap = FrameIdGap(previous_id_, frame_id, frame_id_wrap_);
      if (gap > 0) stats_.missed += gap;
    }
    previous_id_ = frame_id;
    have_previous_id_ = true;
  }

  void Delivered(Frame* frame) {
    frame->index = stats_.delivered++;
    Seen(frame->frame_id);
    last_frame_time_ = Clock::now();
  }

  // Declares the device lost, hands it to the worker for release, and schedules a re-open.
  FrameStatus Lose(const std::string& why) {
    last_error_ = why;
    ++stats_.losses;
    std::uint64_t completed = 0, failures = 0, underruns = 0;
    device_->StreamStatistics(&completed, &failures, &underruns);
    stats_.underruns += static_cast<std::int64_t>(underruns);
    Retire(std::move(device_), /*dead=*/true);
    have_previous_id_ = false;
    backoff_s_ = options_.reconnect_backoff_s;
    next_attempt_ = Clock::now();
    return FrameStatus::kDeviceLost;
  }

  void Retire(std::unique_ptr<AravisDevice> device, bool dead) {
    if (dead) device->MarkDead();
    // The task holds the only reference, so the release (seconds on a dead camera) happens on
    // the worker, never here.
    worker_.Post(
        [shared = std::shared_ptr<AravisDevice>(std::move(device))]() mutable { shared.reset(); });
  }

  // While lost: starts a re-open when one is due, waits for it until `deadline`, and adopts the
  // new device when it succeeded. Returns true when a device is streaming again.
  bool TryRecover(Clock::time_point deadline) {
    if (!pending_open_.valid()) {
      if (Clock::now() < next_attempt_) {
        std::this_thread::sleep_until(std::min(next_attempt_, deadline));
        if (Clock::now() < next_attempt_) return false;
      }
      auto promise = std::make_shared<std::promise<OpenResult>>();
      pending_open_ = promise->get_future();
      const AravisSourceOptions options = options_;
      worker_.Post([promise, options] {
        OpenResult result;
        result.device = AravisDevice::Open(options, &result.error);
        promise->set_value(std::move(result));
      });
      ++stats_.reconnect_attempts;
    }
    if (pending_open_.wait_until(deadline) != std::future_status::ready) return false;
    OpenResult result = pending_open_.get();
    if (!result.device) {
      last_error_ = "re-open failed: " + result.error;
      next_attempt_ = Clock::now() + Seconds(backoff_s_);
      backoff_s_ = std::min(2.0 * backoff_s_, options_.reconnect_backoff_max_s);
      return false;
    }
    device_ = std::move(result.device);
    description_ = device_->description();
    frame_id_wrap_ = device_->frame_id_wrap();
    ++stats_.reconnections;
    last_frame_time_ = Clock::now();
    return true;
  }

  AravisSourceOptions options_;
  std::unique_ptr<AravisDevice> device_;  // null while the camera is lost
  std::string description_;
  std::string last_error_;
  std::uint64_t frame_id_wrap_ = 0;
  SourceStats stats_;
  std::uint64_t previous_id_ = 0;
  bool have_previous_id_ = false;
  Clock::time_point last_frame_time_;
  Clock::time_point next_attempt_;
  double backoff_s_ = 0.0;
  std::future<OpenResult> pending_open_;
  SerialWorker worker_;  // last: destroyed first, so it drains before the members above go
};

AravisSource::AravisSource(const AravisSourceOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
AravisSource::~AravisSource() = default;
FrameStatus AravisSource::Grab(Frame* frame) {
  return impl_->Grab(frame);
}
std::string AravisSource::Describe() const {
  return impl_->Describe();
}
SourceStats AravisSource::Stats() const {
  return impl_->Stats();
}
std::string AravisSource::LastError() const {
  return impl_->LastError();
}
std::uint64_t AravisSource::FrameIdWrap() const {
  return impl_->FrameIdWrap();
}

int AravisSource::WaitingFrames() const {
  return impl_->WaitingFrames();
}

}  // namespace linetrack

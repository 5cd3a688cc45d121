// One interface for every frame source of linetrack: industrial cameras through Aravis, V4L2
// devices, video files and image sequences (replay), and the simulated camera. Every source
// delivers 8-bit grey ViSP images; no call blocks longer than the source's own timeout.
#pragma once

#include <visp3/core/vpImage.h>

#include <cstdint>
#include <string>

namespace linetrack {

// What one Grab() call produced.
enum class FrameStatus {
  kOk,           // *frame holds a new image
  kEndOfStream,  // a file or sequence has no more frames (never for live sources)
  kTimeout,      // no complete frame within the grab timeout; try again
  kDeviceLost,   // the device is gone or stalled; the source keeps retrying on later calls
};

// "ok", "end of stream", "timeout", "device lost".
const char* ToString(FrameStatus status);

// One grey frame and when it was taken.
struct Frame {
  vpImage<unsigned char> image;  // 8-bit grey, converted from the device's pixel format
  // Seconds. The camera's own clock when the device stamps frames (has_camera_timestamp),
  // else the host's time of arrival (live) or index / frame rate (files).
  double timestamp_s = 0.0;
  bool has_camera_timestamp = false;
  double host_time_s = 0.0;  // host real-time clock when the frame was handed over (seconds)
  // The device's own frame id (GigE Vision block id: 1..65535, wrapping to 1; file frame index
  // for files), and the number of frames this source delivered before this one.
  std::uint64_t frame_id = 0;
  std::int64_t index = 0;
};

// Counters a source keeps over its lifetime.
struct SourceStats {
  std::int64_t delivered = 0;           // frames returned with kOk
  std::int64_t missed = 0;              // frames lost before delivery, from the device's frame ids
  std::int64_t skipped = 0;             // frames received but passed over for a newer one
  std::int64_t incomplete = 0;          // buffers dropped because the device marked them bad
  std::int64_t timeouts = 0;            // Grab() calls that returned kTimeout
  std::int64_t losses = 0;              // times the device was declared lost
  std::int64_t reconnections = 0;       // successful re-opens after a loss
  std::int64_t reconnect_attempts = 0;  // re-open attempts (successful or not)
  std::int64_t underruns = 0;           // frames the driver dropped for lack of a free buffer
};

// A source of grey frames. Not thread-safe: one thread calls Grab().
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Waits at most the source's grab timeout for the next frame. On kOk, *frame is overwritten
  // (its image buffer is reused when the size does not change).
  virtual FrameStatus Grab(Frame* frame) = 0;

  // One line for logs: kind, device or file, size and pixel format.
  virtual std::string Describe() const = 0;

  // Counters since the source was opened.
  virtual SourceStats Stats() const = 0;

  // Why the device was last lost or failed to reopen (empty when nothing went wrong).
  virtual std::string LastError() const { return {}; }
};

// Number of frames missing between two consecutive frame ids. Ids run over 1..wrap and the id
// after `wrap` is 1 (GigE Vision: wrap = 65535, id 0 is invalid); wrap = 0 means ids never wrap.
// Returns -1 for a discontinuity (same id, going back, or a jump of more than half the ring),
// which happens when a camera restarts.
std::int64_t FrameIdGap(std::uint64_t previous_id, std::uint64_t id, std::uint64_t wrap);

}  // namespace linetrack

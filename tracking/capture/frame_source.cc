#include "tracking/capture/frame_source.h"

namespace linetrack {

const char* ToString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kEndOfStream:
      return "end of stream";
    case FrameStatus::kTimeout:
      return "timeout";
    case FrameStatus::kDeviceLost:
      return "device lost";
  }
  return "unknown";
}

std::int64_t FrameIdGap(std::uint64_t previous_id, std::uint64_t id, std::uint64_t wrap) {
  if (wrap == 0) {
    if (id <= previous_id) return -1;
    return static_cast<std::int64_t>(id - previous_id - 1);
  }
  if (id == 0 || previous_id == 0 || id > wrap || previous_id > wrap || id == previous_id) {
    return -1;
  }
  // Ids live on the ring 1..wrap: the forward distance from previous_id to id.
  const std::uint64_t forward = (id + wrap - previous_id) % wrap;
  if (forward > wrap / 2) return -1;
  return static_cast<std::int64_t>(forward) - 1;
}

}  // namespace linetrack

// Frames from Video4Linux2 devices (USB webcams, frame grabbers) through ViSP's vpV4l2Grabber,
// converted to grey by ViSP.
#pragma once

#include <memory>
#include <string>

#include "tracking/capture/frame_source.h"

namespace linetrack {

struct V4l2SourceOptions {
  int input = 0;      // device input (0 for webcams)
  int scale = 1;      // 1 = full resolution, 2 = half, 4 = quarter (vpV4l2Grabber's scale)
  int n_buffers = 3;  // driver buffers
  double reopen_backoff_s = 1.0;  // wait between re-open attempts after a failure

  bool Check(std::string* why) const;
};

// A V4L2 device ("/dev/video0"). The constructor throws InputError naming the device when it
// does not exist or cannot be opened. A failing acquisition returns kDeviceLost and the device
// is re-opened on later calls. Grab() has no timeout of its own: vpV4l2Grabber waits up to 30 s
// for a frame from a stalled device (ViSP's select timeout).
class V4l2Source : public FrameSource {
 public:
  V4l2Source(const std::string& device, const V4l2SourceOptions& options);
  ~V4l2Source() override;

  FrameStatus Grab(Frame* frame) override;
  std::string Describe() const override;
  SourceStats Stats() const override;
  std::string LastError() const override;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack

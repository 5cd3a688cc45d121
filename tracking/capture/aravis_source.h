// Frames from GenICam cameras (GigE Vision, USB3 Vision) through libaravis 0.8. The source
// survives the loss of the camera: it reports kDeviceLost, re-opens the camera in the
// background with exponential backoff (attempts are made from Grab() calls only), and resumes.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tracking/capture/frame_source.h"

namespace linetrack {

// How to find and configure the camera. NaN or 0 leaves a setting as the camera has it.
struct AravisSourceOptions {
  // Aravis device id ("Aravis-Fake-SN1"), serial number, physical id (MAC), or IPv4 address of
  // a GigE camera; empty = the first camera found. "Fake_1" opens Aravis' in-process fake
  // camera (the "Fake" interface is enabled for it).
  std::string device_id;
  std::string pixel_format;    // GenICam name ("Mono8", "BayerRG8", "RGB8", ...); "" = keep
  int width = 0;               // pixels; 0 = keep (region set from offset 0,0)
  int height = 0;              // pixels; 0 = keep
  double frame_rate = 0.0;     // frames/s; 0 = keep
  double exposure_us = 0.0;    // microseconds; 0 = keep
  double gain = std::nan("");  // camera gain units (often dB); NaN = keep
  int packet_size = 0;         // GigE stream packet bytes; 0 = keep, -1 = negotiate (auto)
  int n_buffers = 8;           // buffers in the stream pool
  // Deliver the newest complete frame: older frames still queued when Grab() is called are
  // skipped (SourceStats::skipped). For control loops slower than the camera, which would
  // otherwise work on frames up to n_buffers periods old. Off: every frame, in order.
  bool latest_only = false;
  double grab_timeout_s = 0.5;           // longest a Grab() call waits
  double loss_timeout_s = 1.0;           // no complete frame for this long: the camera is lost
  double reconnect_backoff_s = 0.25;     // first wait between re-open attempts
  double reconnect_backoff_max_s = 4.0;  // the wait doubles up to this

  // False with *why set when a value is out of range (names the field).
  bool Check(std::string* why) const;
};

// A camera Aravis can see.
struct AravisDeviceInfo {
  std::string id, physical_id, address, vendor, model, serial, protocol;
};

// Scans all Aravis interfaces (about one second for GigE discovery). `include_fake` enables
// the in-process "Fake" interface first.
std::vector<AravisDeviceInfo> ListAravisDevices(bool include_fake = false);

// A frame source on an Aravis camera. The constructor opens and starts the camera and throws
// InputError naming the device when it cannot be found or configured; later losses are
// reported by Grab() and recovered from.
class AravisSource : public FrameSource {
 public:
  explicit AravisSource(const AravisSourceOptions& options);
  ~AravisSource() override;
  AravisSource(const AravisSource&) = delete;
  AravisSource& operator=(const AravisSource&) = delete;

  FrameStatus Grab(Frame* frame) override;
  std::string Describe() const override;
  SourceStats Stats() const override;
  std::string LastError() const override;

  // Wrap of the device's frame ids (65535 for GigE Vision and the fake camera, 0 = none).
  std::uint64_t FrameIdWrap() const;

  // Frames received and waiting for Grab() (0 while the camera is lost): how far behind the
  // consumer is.
  int WaitingFrames() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace linetrack

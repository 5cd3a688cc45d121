// Internal to the Aravis source: one opened, configured and streaming Aravis camera (RAII over
// ArvCamera and ArvStream). Include only from .cc files: it exposes <arv.h>.
#pragma once

#include <arv.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "tracking/capture/aravis_source.h"
#include "tracking/capture/pixel_convert.h"

namespace linetrack::internal {

// Maps an Aravis (PFNC) pixel format to linetrack's; false when it cannot be converted.
bool PixelFormatFromArv(ArvPixelFormat arv_format, PixelFormat* format);

// Finds the device named by `device_id` (see AravisSourceOptions::device_id) and returns in
// *open_name what to pass to arv_camera_new: the IPv4 address for GigE Vision cameras (Aravis
// then binds the stream to the interface that reaches the camera), else the Aravis device id.
bool ResolveAravisDevice(const std::string& device_id, std::string* open_name, std::string* why);

class AravisDevice {
 public:
  // Resolves, opens, configures and starts the camera; nullptr with *why set on failure.
  static std::unique_ptr<AravisDevice> Open(const AravisSourceOptions& options, std::string* why);

  // Stops the acquisition (unless the device was marked dead: that would block on timeouts)
  // and releases the stream and the camera. May block for a few seconds on a dead GigE camera.
  ~AravisDevice();
  AravisDevice(const AravisDevice&) = delete;
  AravisDevice& operator=(const AravisDevice&) = delete;

  // The next filled buffer, or nullptr after `timeout_s`. Give it back with Push().
  ArvBuffer* Pop(double timeout_s);
  ArvBuffer* TryPop();         // a buffer already waiting in the output queue, or nullptr
  int WaitingBuffers() const;  // buffers in the output queue (filled, not yet popped)
  void Push(ArvBuffer* buffer);

  // Converts a SUCCESS buffer to a grey frame (image, timestamps, frame id).
  bool ToFrame(ArvBuffer* buffer, Frame* frame, std::string* why) const;

  // True once Aravis emitted "control-lost" (the GigE heartbeat failed).
  bool ControlLost() const { return control_lost_.load(); }
  // Skip stopping the acquisition at destruction (the camera does not answer any more).
  void MarkDead() { dead_ = true; }

  // Driver-side counters: frames completed, failed and dropped for lack of buffers.
  void StreamStatistics(std::uint64_t* completed, std::uint64_t* failures,
                        std::uint64_t* underruns) const;

  const std::string& description() const { return description_; }
  std::uint64_t frame_id_wrap() const { return frame_id_wrap_; }

 private:
  explicit AravisDevice(ArvCamera* camera) : camera_(camera) {}
  bool Configure(const AravisSourceOptions& options, std::string* why);
  bool Start(const AravisSourceOptions& options, std::string* why);
  static void OnControlLost(ArvDevice* device, gpointer self);

  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  gulong control_lost_handler_ = 0;
  std::atomic<bool> control_lost_{false};
  bool dead_ = false;
  bool acquiring_ = false;
  std::uint64_t frame_id_wrap_ = 0;
  std::string description_;
};

}  // namespace linetrack::internal

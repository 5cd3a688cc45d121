#include "tracking/capture/aravis_device.h"

#include <arpa/inet.h>

#include <cmath>
#include <sstream>

namespace linetrack::internal {
namespace {

// Takes the message out of *error (and clears it); "" when there was no error.
std::string TakeError(GError** error) {
  if (*error == nullptr) return {};
  std::string message = (*error)->message ? (*error)->message : "unknown Aravis error";
  g_clear_error(error);
  return message.empty() ? "unknown Aravis error" : message;
}

std::string Str(const char* s) {
  return s ? s : "";
}

bool IsIpv4Address(const std::string& text) {
  in_addr address{};
  return inet_pton(AF_INET, text.c_str(), &address) == 1;
}

// Checks `value` against the feature's bounds so that a bad option names the valid range
// instead of being silently clamped by the camera.
bool WithinBounds(const char* name, double value, double lo, double hi, std::string* why) {
  if (value >= lo && value <= hi) return true;
  std::ostringstream out;
  out << name << " " << value << " outside the camera's range [" << lo << ", " << hi << "]";
  *why = out.str();
  return false;
}

// A floating-point camera feature with bounds and, maybe, an automatic mode to switch off.
struct BoundedFeature {
  const char* name;
  gboolean (*auto_available)(ArvCamera*, GError**);  // null: no automatic mode
  void (*set_auto)(ArvCamera*, ArvAuto, GError**);
  void (*bounds)(ArvCamera*, double*, double*, GError**);
  void (*set)(ArvCamera*, double, GError**);
};

constexpr BoundedFeature kFrameRate = {
    "frame rate", nullptr, nullptr, &arv_camera_get_frame_rate_bounds, &arv_camera_set_frame_rate};
constexpr BoundedFeature kExposure = {
    "exposure (us)", &arv_camera_is_exposure_auto_available, &arv_camera_set_exposure_time_auto,
    &arv_camera_get_exposure_time_bounds, &arv_camera_set_exposure_time};
constexpr BoundedFeature kGain = {"gain", &arv_camera_is_gain_auto_available,
                                  &arv_camera_set_gain_auto, &arv_camera_get_gain_bounds,
                                  &arv_camera_set_gain};

// Switches the automatic mode off, checks `value` against the bounds, and sets it.
bool SetBounded(ArvCamera* camera, const BoundedFeature& feature, double value, std::string* why) {
  if (feature.auto_available != nullptr && feature.auto_available(camera, nullptr)) {
    feature.set_auto(camera, ARV_AUTO_OFF, nullptr);
  }
  GError* error = nullptr;
  double lo = 0.0, hi = 0.0;
  feature.bounds(camera, &lo, &hi, &error);
  std::string message = TakeError(&error);
  if (message.empty() && !WithinBounds(feature.name, value, lo, hi, why)) return false;
  if (message.empty()) {
    feature.set(camera, value, &error);
    message = TakeError(&error);
  }
  if (message.empty()) return true;
  *why = std::string(feature.name) + ": " + message;
  return false;
}

}  // namespace

bool PixelFormatFromArv(ArvPixelFormat arv_format, PixelFormat* format) {
  static const struct {
    ArvPixelFormat arv;
    PixelFormat ours;
  } kTable[] = {
      {ARV_PIXEL_FORMAT_MONO_8, {PixelKind::kMono, 8}},
      {ARV_PIXEL_FORMAT_MONO_10, {PixelKind::kMono, 10}},
      {ARV_PIXEL_FORMAT_MONO_12, {PixelKind::kMono, 12}},
      {ARV_PIXEL_FORMAT_MONO_14, {PixelKind::kMono, 14}},
      {ARV_PIXEL_FORMAT_MONO_16, {PixelKind::kMono, 16}},
      {ARV_PIXEL_FORMAT_BAYER_RG_8, {PixelKind::kBayerRG, 8}},
      {ARV_PIXEL_FORMAT_BAYER_GR_8, {PixelKind::kBayerGR, 8}},
      {ARV_PIXEL_FORMAT_BAYER_GB_8, {PixelKind::kBayerGB, 8}},
      {ARV_PIXEL_FORMAT_BAYER_BG_8, {PixelKind::kBayerBG, 8}},
      {ARV_PIXEL_FORMAT_BAYER_RG_10, {PixelKind::kBayerRG, 10}},
      {ARV_PIXEL_FORMAT_BAYER_GR_10, {PixelKind::kBayerGR, 10}},
      {ARV_PIXEL_FORMAT_BAYER_GB_10, {PixelKind::kBayerGB, 10}},
      {ARV_PIXEL_FORMAT_BAYER_BG_10, {PixelKind::kBayerBG, 10}},
      {ARV_PIXEL_FORMAT_BAYER_RG_12, {PixelKind::kBayerRG, 12}},
      {ARV_PIXEL_FORMAT_BAYER_GR_12, {PixelKind::kBayerGR, 12}},
      {ARV_PIXEL_FORMAT_BAYER_GB_12, {PixelKind::kBayerGB, 12}},
      {ARV_PIXEL_FORMAT_BAYER_BG_12, {PixelKind::kBayerBG, 12}},
      {ARV_PIXEL_FORMAT_BAYER_RG_16, {PixelKind::kBayerRG, 16}},
      {ARV_PIXEL_FORMAT_BAYER_GR_16, {PixelKind::kBayerGR, 16}},
      {ARV_PIXEL_FORMAT_BAYER_GB_16, {PixelKind::kBayerGB, 16}},
      {ARV_PIXEL_FORMAT_BAYER_BG_16, {PixelKind::kBayerBG, 16}},
      {ARV_PIXEL_FORMAT_RGB_8_PACKED, {PixelKind::kRgb, 8}},
      {ARV_PIXEL_FORMAT_BGR_8_PACKED, {PixelKind::kBgr, 8}},
  };
  for (const auto& entry : kTable) {
    if (entry.arv == arv_format) {
      *format = entry.ours;
      return true;
    }
  }
  return false;
}

bool ResolveAravisDevice(const std::string& device_id, std::string* open_name, std::string* why) {
  if (IsIpv4Address(device_id)) {
    *open_name = device_id;
    return true;
  }
  if (device_id.rfind("Fake_", 0) == 0) {
    // Aravis' in-process fake camera: no discovery round needed.
    arv_enable_interface("Fake");
    *open_name = device_id;
    return true;
  }
  arv_update_device_list();
  const unsigned n = arv_get_n_devices();
  int found = -1;
  std::string seen;
  for (unsigned i = 0; i < n; ++i) {
    const std::string id = Str(arv_get_device_id(i));
    seen += (seen.empty() ? "" : ", ") + id;
    if (found >= 0) continue;
    if (device_id.empty() || device_id == id || device_id == Str(arv_get_device_serial_nbr(i)) ||
        device_id == Str(arv_get_device_physical_id(i)) ||
        device_id == Str(arv_get_device_address(i))) {
      found = static_cast<int>(i);
    }
  }
  if (found < 0) {
    *why = (device_id.empty() ? std::string("no camera found")
                              : "no camera '" + device_id + "' found") +
           (n == 0 ? " (Aravis sees no camera)" : " (Aravis sees: " + seen + ")");
    return false;
  }
  const std::string address = Str(arv_get_device_address(found));
  if (Str(arv_get_device_protocol(found)) == "GigEVision" && IsIpv4Address(address)) {
    *open_name = address;
  } else {
    *open_name = Str(arv_get_device_id(found));
  }
  return true;
}

std::unique_ptr<AravisDevice> AravisDevice::Open(const AravisSourceOptions& options,
                                                 std::string* why) {
  std::string open_name;
  if (!ResolveAravisDevice(options.device_id, &open_name, why)) return nullptr;
  GError* error = nullptr;
  ArvCamera* camera = arv_camera_new(open_name.c_str(), &error);
  if (camera == nullptr) {
    *why = "cannot open camera '" + open_name + "': " + TakeError(&error);
    return nullptr;
  }
  std::unique_ptr<AravisDevice> device(new AravisDevice(camera));
  if (!device->Configure(options, why) || !device->Start(options, why)) return nullptr;
  return device;
}

bool AravisDevice::Configure(const AravisSourceOptions& o, std::string* why) {
  GError* error = nullptr;
  auto failed = [&](const std::string& what) {
    const std::string message = TakeError(&error);
    if (message.empty()) return false;
    *why = what + ": " + message;
    return true;
  };
  if (!o.pixel_format.empty()) {
    arv_camera_set_pixel_format_from_string(camera_, o.pixel_format.c_str(), &error);
    if (failed("PixelFormat " + o.pixel_format)) return false;
  }
  if (o.width > 0 || o.height > 0) {
    gint x = 0, y = 0, w = 0, h = 0;
    arv_camera_get_region(camera_, &x, &y, &w, &h, &error);
    if (failed("region")) return false;
    gint w_min = 0, w_max = 0, h_min = 0, h_max = 0;
    arv_camera_get_width_bounds(camera_, &w_min, &w_max, nullptr);
    arv_camera_get_height_bounds(camera_, &h_min, &h_max, nullptr);
    const int width = o.width > 0 ? o.width : w;
    const int height = o.height > 0 ? o.height : h;
    if (!WithinBounds("width", width, w_min, w_max, why) ||
        !WithinBounds("height", height, h_min, h_max, why)) {
      return false;
    }
    arv_camera_set_region(camera_, 0, 0, width, height, &error);
    if (failed("region " + std::to_string(width) + "x" + std::to_string(height))) return false;
  }
  if (o.frame_rate > 0.0 && !SetBounded(camera_, kFrameRate, o.frame_rate, why)) return false;
  if (o.exposure_us > 0.0 && !SetBounded(camera_, kExposure, o.exposure_us, why)) return false;
  if (!std::isnan(o.gain) && !SetBounded(camera_, kGain, o.gain, why)) return false;
  const bool gige = arv_camera_is_gv_device(camera_);
  if (gige && o.packet_size > 0) {
    arv_camera_gv_set_packet_size(camera_, o.packet_size, &error);
    if (failed("packet size")) return false;
  } else if (gige && o.packet_size < 0) {
    arv_camera_gv_auto_packet_size(camera_, &error);
    if (failed("packet size negotiation")) return false;
  }
  arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  if (failed("acquisition mode")) return false;

  const std::string format_name = Str(arv_camera_get_pixel_format_as_string(camera_, nullptr));
  PixelFormat format;
  if (!PixelFormatFromArv(arv_camera_get_pixel_format(camera_, nullptr), &format)) {
    *why = "pixel format '" + format_name +
           "' cannot be converted to grey (use Mono8..16, Bayer*8..16, RGB8 or BGR8)";
    return false;
  }
  gint x = 0, y = 0, width = 0, height = 0;
  arv_camera_get_region(camera_, &x, &y, &width, &height, nullptr);
  const std::string model = Str(arv_camera_get_model_name(camera_, nullptr));
  // GigE Vision block ids are 16 bits (1..65535); Aravis' fake cameras wrap the same way.
  frame_id_wrap_ = (gige || model == "Fake") ? 65535 : 0;
  std::ostringstream text;
  text << "aravis:" << Str(arv_camera_get_device_id(camera_, nullptr)) << " ("
       << Str(arv_camera_get_vendor_name(camera_, nullptr)) << " " << model << ", " << width << "x"
       << height << " " << format_name;
  if (arv_camera_is_frame_rate_available(camera_, nullptr)) {
    text << ", " << arv_camera_get_frame_rate(camera_, nullptr) << " fps";
  }
  text << ")";
  description_ = text.str();
  return true;
}

bool AravisDevice::Start(const AravisSourceOptions& o, std::string* why) {
  GError* error = nullptr;
  stream_ = arv_camera_create_stream(camera_, nullptr, nullptr, &error);
  if (stream_ == nullptr) {
    *why = "cannot create the stream: " + TakeError(&error);
    return false;
  }
  const guint payload = arv_camera_get_payload(camera_, &error);
  if (payload == 0) {
    *why = "payload size unknown: " + TakeError(&error);
    return false;
  }
  for (int i = 0; i < o.n_buffers; ++i) {
    arv_stream_push_buffer(stream_, arv_buffer_new_allocate(payload));
  }
  control_lost_handler_ = g_signal_connect(arv_camera_get_device(camera_), "control-lost",
                                           G_CALLBACK(&AravisDevice::OnControlLost), this);
  arv_camera_start_acquisition(camera_, &error);
  const std::string message = TakeError(&error);
  if (!message.empty()) {
    *why = "cannot start the acquisition: " + message;
    return false;
  }
  acquiring_ = true;
  return true;
}

void AravisDevice::OnControlLost(ArvDevice* /*device*/, gpointer self) {
  static_cast<AravisDevice*>(self)->control_lost_.store(true);
}

AravisDevice::~AravisDevice() {
  if (camera_ != nullptr && acquiring_ && !dead_) {
    arv_camera_stop_acquisition(camera_, nullptr);
  }
  if (camera_ != nullptr && control_lost_handler_ != 0) {
    g_signal_handler_disconnect(arv_camera_get_device(camera_), control_lost_handler_);
  }
  // The stream owns the buffers still queued in it; buffers are never held outside Pop/Push.
  if (stream_ != nullptr) g_object_unref(stream_);
  if (camera_ != nullptr) g_object_unref(camera_);
}

ArvBuffer* AravisDevice::Pop(double timeout_s) {
  const guint64 timeout_us = timeout_s > 0.0 ? static_cast<guint64>(timeout_s * 1e6) : 1;
  return arv_stream_timeout_pop_buffer(stream_, timeout_us);
}

ArvBuffer* AravisDevice::TryPop() {
  return arv_stream_try_pop_buffer(stream_);
}

int AravisDevice::WaitingBuffers() const {
  gint n_input = 0, n_output = 0;
  arv_stream_get_n_buffers(stream_, &n_input, &n_output);
  return n_output;
}

void AravisDevice::Push(ArvBuffer* buffer) {
  arv_stream_push_buffer(stream_, buffer);
}

bool AravisDevice::ToFrame(ArvBuffer* buffer, Frame* frame, std::string* why) const {
  RawImage raw;
  if (!PixelFormatFromArv(arv_buffer_get_image_pixel_format(buffer), &raw.format)) {
    *why = "unsupported pixel format in buffer";
    return false;
  }
  std::size_t size = 0;
  raw.data = static_cast<const std::uint8_t*>(arv_buffer_get_image_data(buffer, &size));
  raw.size_bytes = size;
  raw.width = arv_buffer_get_image_width(buffer);
  raw.height = arv_buffer_get_image_height(buffer);
  gint x_padding = 0, y_padding = 0;
  arv_buffer_get_image_padding(buffer, &x_padding, &y_padding);
  raw.stride_bytes =
      static_cast<std::size_t>(raw.width) * raw.format.BytesPerPixel() + std::max(0, x_padding);
  if (!ConvertToGrey(raw, &frame->image, why)) return false;
  const guint64 camera_ns = arv_buffer_get_timestamp(buffer);
  const guint64 host_ns = arv_buffer_get_system_timestamp(buffer);
  frame->host_time_s = host_ns != 0 ? 1e-9 * static_cast<double>(host_ns)
                                    : 1e-6 * static_cast<double>(g_get_real_time());
  frame->has_camera_timestamp = camera_ns != 0;
  frame->timestamp_s = camera_ns != 0 ? 1e-9 * static_cast<double>(camera_ns) : frame->host_time_s;
  frame->frame_id = arv_buffer_get_frame_id(buffer);
  return true;
}

void AravisDevice::StreamStatistics(std::uint64_t* completed, std::uint64_t* failures,
                                    std::uint64_t* underruns) const {
  guint64 c = 0, f = 0, u = 0;
  arv_stream_get_statistics(stream_, &c, &f, &u);
  *completed = c;
  *failures = f;
  *underruns = u;
}

}  // namespace linetrack::internal

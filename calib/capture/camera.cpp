#include "rigcal/capture/camera.h"

#include <arv.h>
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <mutex>

#include "rigcal/core/error.h"

namespace rigcal::capture {
namespace {

std::string text_or_empty(const char* s) { return s ? std::string(s) : std::string(); }

// Takes a GError's message and clears it; "" when there was none.
std::string take_error(GError*& error) {
  if (!error) return {};
  std::string message = error->message ? error->message : "unknown error";
  g_clear_error(&error);
  return message;
}

std::vector<std::string> pixel_formats_of(ArvCamera* camera) {
  std::vector<std::string> out;
  GError* error = nullptr;
  guint n = 0;
  const char** names = arv_camera_dup_available_pixel_formats_as_strings(camera, &n, &error);
  take_error(error);
  for (guint i = 0; names && i < n; ++i) out.push_back(text_or_empty(names[i]));
  g_free(names);
  return out;
}

std::optional<double> as_number(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(x)) return std::nullopt;
  return x;
}

// The significant bits of an unpacked pixel format's name ("BayerRG12" -> 12, "Mono8" -> 8).
int significant_bits(const std::string& name) {
  size_t i = name.size();
  while (i > 0 && std::isdigit(static_cast<unsigned char>(name[i - 1]))) --i;
  return i < name.size() ? std::atoi(name.c_str() + i) : 0;
}

std::string status_name(ArvBufferStatus status) {
  switch (status) {
    case ARV_BUFFER_STATUS_CLEARED:
      return "cleared";
    case ARV_BUFFER_STATUS_TIMEOUT:
      return "timeout (not every packet arrived in time)";
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      return "missing packets";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID:
      return "wrong packet id";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH:
      return "larger than the buffer";
    case ARV_BUFFER_STATUS_FILLING:
      return "still filling";
    case ARV_BUFFER_STATUS_ABORTED:
      return "aborted";
    default:
      return fmt::format("status {}", static_cast<int>(status));
  }
}

}  // namespace

std::string_view to_string(FeatureResult::Status status) {
  switch (status) {
    case FeatureResult::Status::set:
      return "set";
    case FeatureResult::Status::adjusted:
      return "adjusted";
    case FeatureResult::Status::absent:
      return "absent";
    case FeatureResult::Status::refused:
      return "refused";
  }
  return "?";
}

std::string describe(const CameraInfo& info) {
  return fmt::format("{}: {} {}, serial {}", info.id, info.vendor, info.model,
                     info.serial.empty() ? "unknown" : info.serial);
}

void enable_fake_interface() { arv_enable_interface("Fake"); }

std::vector<CameraInfo> list_cameras(bool open_each, bool include_fake) {
  if (include_fake) enable_fake_interface();
  arv_update_device_list();
  std::vector<CameraInfo> out;
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) {
    CameraInfo c;
    c.id = text_or_empty(arv_get_device_id(i));
    c.vendor = text_or_empty(arv_get_device_vendor(i));
    c.model = text_or_empty(arv_get_device_model(i));
    c.serial = text_or_empty(arv_get_device_serial_nbr(i));
    c.address = text_or_empty(arv_get_device_address(i));
    c.protocol = text_or_empty(arv_get_device_protocol(i));
    if (c.protocol == "Fake" && !include_fake) continue;
    if (open_each) {
      GError* error = nullptr;
      ArvCamera* camera = arv_camera_new(c.id.c_str(), &error);
      take_error(error);
      if (camera) {
        c.pixel_formats = pixel_formats_of(camera);
        g_object_unref(camera);
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

struct Camera::Impl {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong lost_handler = 0;
  CameraInfo info;
  std::atomic<bool> lost{false};
  std::mutex control;        // the control channel: features and triggers from two threads
  std::string pixel_format;  // as the stream started
  bool stopped = false;      // the acquisition

  static void on_control_lost(ArvDevice*, gpointer self) { static_cast<Impl*>(self)->lost = true; }
  ArvDevice* device() const { return arv_camera_get_device(camera); }
  std::string name() const { return fmt::format("camera '{}'", info.id); }
};

Camera::Camera(const std::string& id) : impl_(std::make_unique<Impl>()) {
  // Opened directly (a few milliseconds); the device list (a second of discovery) only names the
  // cameras seen when the open fails.
  GError* error = nullptr;
  impl_->camera = arv_camera_new(id.c_str(), &error);
  const std::string why = take_error(error);
  if (!impl_->camera) {
    std::string seen;
    for (const CameraInfo& c : list_cameras(false))
      seen += fmt::format("{}{} ({})", seen.empty() ? "" : ", ", c.id, c.address);
    throw Error(
        fmt::format("camera '{}' could not be opened: {} (Aravis sees {}; `rigcal capture "
                    "--list` lists them)",
                    id, why.empty() ? "no reason given" : why, seen.empty() ? "no camera" : seen));
  }
  CameraInfo& info = impl_->info;
  info.id = id;
  info.vendor = text_or_empty(arv_camera_get_vendor_name(impl_->camera, &error));
  take_error(error);
  info.model = text_or_empty(arv_camera_get_model_name(impl_->camera, &error));
  take_error(error);
  info.serial = text_or_empty(arv_camera_get_device_serial_number(impl_->camera, &error));
  take_error(error);
  ArvDevice* device = impl_->device();
  if (ARV_IS_GV_DEVICE(device)) {
    info.protocol = "GigEVision";
    GSocketAddress* address = arv_gv_device_get_device_address(ARV_GV_DEVICE(device));
    if (address && G_IS_INET_SOCKET_ADDRESS(address)) {
      char* text = g_inet_address_to_string(
          g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(address)));
      info.address = text_or_empty(text);
      g_free(text);
    }
  } else if (ARV_IS_UV_DEVICE(device)) {
    info.protocol = "USB3Vision";
  } else if (ARV_IS_FAKE_DEVICE(device)) {
    info.protocol = "Fake";
  }
  // A value out of a feature's range is an error, not stored as it is.
  arv_camera_set_range_check_policy(impl_->camera, ARV_RANGE_CHECK_POLICY_ENABLE);
  impl_->info.pixel_formats = pixel_formats_of(impl_->camera);
  impl_->lost_handler = g_signal_connect(impl_->device(), "control-lost",
                                         G_CALLBACK(&Impl::on_control_lost), impl_.get());
}

Camera::~Camera() {
  stop();
  if (impl_->camera) {
    if (impl_->lost_handler) g_signal_handler_disconnect(impl_->device(), impl_->lost_handler);
    g_object_unref(impl_->camera);
  }
}

const CameraInfo& Camera::info() const { return impl_->info; }

namespace {
ArvGcFeatureNode* feature_node(ArvDevice* device, const std::string& name) {
  ArvGcNode* node = arv_device_get_feature(device, name.c_str());
  if (!node || !ARV_IS_GC_FEATURE_NODE(node)) return nullptr;
  ArvGcFeatureNode* feature = ARV_GC_FEATURE_NODE(node);
  GError* error = nullptr;
  const bool implemented = arv_gc_feature_node_is_implemented(feature, &error);
  take_error(error);
  const bool available = arv_gc_feature_node_is_available(feature, &error);
  take_error(error);
  return implemented && available ? feature : nullptr;
}
}  // namespace

bool Camera::has(const std::string& feature) const {
  std::lock_guard lock(impl_->control);
  return feature_node(impl_->device(), feature) != nullptr;
}

std::optional<std::string> Camera::get(const std::string& feature) const {
  std::lock_guard lock(impl_->control);
  ArvGcFeatureNode* node = feature_node(impl_->device(), feature);
  if (!node) return std::nullopt;
  GError* error = nullptr;
  const char* value = arv_gc_feature_node_get_value_as_string(node, &error);
  if (!take_error(error).empty() || !value) return std::nullopt;
  return std::string(value);
}

FeatureResult Camera::set(const std::vector<std::string>& alternatives, const std::string& value,
                          bool required, const std::string& why) {
  std::lock_guard lock(impl_->control);
  FeatureResult r;
  r.asked = value;
  r.required = required;
  r.why = why;
  ArvGcFeatureNode* node = nullptr;
  for (const std::string& name : alternatives)
    if ((node = feature_node(impl_->device(), name))) {
      r.feature = name;
      break;
    }
  if (!node) {
    r.status = FeatureResult::Status::absent;
    for (const std::string& name : alternatives)
      r.feature += (r.feature.empty() ? "" : " | ") + name;
    return r;
  }
  std::string text = value;
  if (ARV_IS_GC_BOOLEAN(node)) {
    // Aravis takes "true" alone as true: anything else, "True" or "1", would set false.
    std::string lower;
    for (char ch : value) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (lower == "true" || lower == "yes" || lower == "on" || lower == "1") text = "true";
    if (lower == "false" || lower == "no" || lower == "off" || lower == "0") text = "false";
  }
  GError* error = nullptr;
  arv_gc_feature_node_set_value_from_string(node, text.c_str(), &error);
  const std::string refused = take_error(error);
  const char* back = arv_gc_feature_node_get_value_as_string(node, &error);
  take_error(error);
  r.accepted = text_or_empty(back);
  if (!refused.empty()) {
    r.status = FeatureResult::Status::refused;
    r.camera_says = refused;
    return r;
  }
  const std::optional<double> a = as_number(value), b = as_number(r.accepted);
  if (a && b) {
    const double tolerance = 1e-3 * std::max(1.0, std::abs(*a));
    r.status = std::abs(*a - *b) <= tolerance ? FeatureResult::Status::set
                                              : FeatureResult::Status::adjusted;
  } else {
    r.status = r.accepted == text ? FeatureResult::Status::set : FeatureResult::Status::refused;
  }
  return r;
}

bool Camera::execute(const std::string& command) {
  std::lock_guard lock(impl_->control);
  GError* error = nullptr;
  arv_device_execute_command(impl_->device(), command.c_str(), &error);
  return take_error(error).empty();
}

void Camera::start(int buffers) {
  std::lock_guard lock(impl_->control);
  GError* error = nullptr;
  const guint payload = arv_camera_get_payload(impl_->camera, &error);
  std::string why = take_error(error);
  impl_->pixel_format = text_or_empty(arv_camera_get_pixel_format_as_string(impl_->camera, &error));
  take_error(error);
  if (why.empty()) {
    impl_->stream = arv_camera_create_stream(impl_->camera, nullptr, nullptr, &error);
    why = take_error(error);
  }
  if (!impl_->stream)
    throw Error(
        fmt::format("{}: no stream: {}", impl_->name(), why.empty() ? "no reason given" : why));
  // An ordinary socket's default buffer (212,992 bytes) is smaller than one frame: without this
  // a non-root process loses nearly every frame to missing packets (doc/capture.md).
  if (ARV_IS_GV_STREAM(impl_->stream))
    g_object_set(impl_->stream, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_AUTO, nullptr);
  for (int i = 0; i < buffers; ++i)
    arv_stream_push_buffer(impl_->stream, arv_buffer_new_allocate(payload));
  arv_camera_set_acquisition_mode(impl_->camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  why = take_error(error);
  if (why.empty()) {
    arv_camera_start_acquisition(impl_->camera, &error);
    why = take_error(error);
  }
  if (!why.empty()) throw Error(fmt::format("{}: acquisition not started: {}", impl_->name(), why));
  impl_->stopped = false;
}

StreamEvent Camera::next(double timeout_s) {
  StreamEvent e;
  if (!impl_->stream) return e;
  ArvBuffer* buffer =
      arv_stream_timeout_pop_buffer(impl_->stream, static_cast<guint64>(timeout_s * 1e6));
  if (!buffer) return e;
  const ArvBufferStatus status = arv_buffer_get_status(buffer);
  if (status != ARV_BUFFER_STATUS_SUCCESS ||
      arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE) {
    e.kind = StreamEvent::Kind::incomplete;
    e.frame_id = arv_buffer_get_frame_id(buffer);
    e.status = status == ARV_BUFFER_STATUS_SUCCESS ? "not an image" : status_name(status);
    arv_stream_push_buffer(impl_->stream, buffer);
    return e;
  }
  Frame& f = e.frame;
  f.frame_id = arv_buffer_get_frame_id(buffer);
  f.device_stamp = Time::from_ns(static_cast<int64_t>(arv_buffer_get_timestamp(buffer)));
  f.host_stamp = Time::from_ns(static_cast<int64_t>(arv_buffer_get_system_timestamp(buffer)));
  const ArvPixelFormat format = arv_buffer_get_image_pixel_format(buffer);
  f.pixel_format = impl_->pixel_format;
  const int width = arv_buffer_get_image_width(buffer),
            height = arv_buffer_get_image_height(buffer);
  const int container = ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format);
  gint x_padding = 0, y_padding = 0;
  arv_buffer_get_image_padding(buffer, &x_padding, &y_padding);
  size_t size = 0;
  const auto* data = static_cast<const uint8_t*>(arv_buffer_get_image_data(buffer, &size));
  const size_t bytes = container / 8;
  const size_t stride =
      static_cast<size_t>(width) * bytes + static_cast<size_t>(std::max(0, x_padding));
  if ((container != 8 && container != 16) || width <= 0 || height <= 0 || !data ||
      size < stride * (height - 1) + width * bytes) {
    e.kind = StreamEvent::Kind::incomplete;
    e.frame_id = f.frame_id;
    e.status = container != 8 && container != 16
                   ? fmt::format("pixel format 0x{:08x} is packed or colour: not recorded", format)
                   : "image smaller than its size";
    arv_stream_push_buffer(impl_->stream, buffer);
    return e;
  }
  cv::Mat wrapped(height, width, container == 8 ? CV_8UC1 : CV_16UC1, const_cast<uint8_t*>(data),
                  stride);
  f.image = wrapped.clone();
  const int bits = significant_bits(impl_->pixel_format);
  if (container == 16 && bits > 8 && bits < 16) f.image *= 1 << (16 - bits);
  arv_stream_push_buffer(impl_->stream, buffer);
  e.kind = StreamEvent::Kind::frame;
  return e;
}

bool Camera::software_trigger() {
  std::lock_guard lock(impl_->control);
  GError* error = nullptr;
  arv_camera_software_trigger(impl_->camera, &error);
  return take_error(error).empty();
}

void Camera::stop_acquisition() {
  if (!impl_ || !impl_->stream || impl_->stopped) return;
  std::lock_guard lock(impl_->control);
  GError* error = nullptr;
  if (!impl_->lost) arv_camera_stop_acquisition(impl_->camera, &error);
  take_error(error);
  impl_->stopped = true;
}

void Camera::stop() {
  if (!impl_ || !impl_->stream) return;
  stop_acquisition();
  g_object_unref(impl_->stream);
  impl_->stream = nullptr;
}

bool Camera::lost() const { return impl_->lost; }

void* Camera::aravis_device() const { return impl_->device(); }

}  // namespace rigcal::capture

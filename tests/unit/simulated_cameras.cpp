#include "simulated_cameras.h"

#include <arv.h>

#include <chrono>
#include <cstring>
#include <mutex>
#include <thread>

namespace rigcal::test {
namespace {

// What a fill callback needs. Aravis 0.8's fill callback cannot set how much of the buffer it
// filled (the buffer's received size is private), so a second fake camera with Aravis' own
// pattern fills the buffer first (that sets the size) and the pattern then draws over it, with the
// frame's id and stamps put back.
struct Drawing {
  FramePattern pattern;
  ArvFakeCamera* sizer = nullptr;
  std::atomic<size_t> frames{0};
  ~Drawing() {
    if (sizer) g_object_unref(sizer);
  }
};

void fill(ArvBuffer* buffer, void* data, guint32, guint32, ArvPixelFormat format) {
  auto* d = static_cast<Drawing*>(data);
  ++d->frames;
  const guint64 id = arv_buffer_get_frame_id(buffer);
  const guint64 stamp = arv_buffer_get_timestamp(buffer);
  const guint64 system = arv_buffer_get_system_timestamp(buffer);
  const int width = arv_buffer_get_image_width(buffer),
            height = arv_buffer_get_image_height(buffer);
  arv_fake_camera_write_register(d->sizer, ARV_FAKE_CAMERA_REGISTER_WIDTH, width);
  arv_fake_camera_write_register(d->sizer, ARV_FAKE_CAMERA_REGISTER_HEIGHT, height);
  arv_fake_camera_write_register(d->sizer, ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT, format);
  arv_fake_camera_fill_buffer(d->sizer, buffer, nullptr);
  arv_buffer_set_frame_id(buffer, id);
  arv_buffer_set_timestamp(buffer, stamp);
  arv_buffer_set_system_timestamp(buffer, system);
  if (!d->pattern) return;
  size_t size = 0;
  auto* pixels = static_cast<uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &size)));
  const int bits = ARV_PIXEL_FORMAT_BIT_PER_PIXEL(format);
  if (!pixels || (bits != 8 && bits != 16) || size < size_t(width) * height * (bits / 8)) return;
  cv::Mat image(height, width, bits == 8 ? CV_8UC1 : CV_16UC1, pixels);
  d->pattern(id, Time::from_ns(static_cast<int64_t>(stamp)), image);
}

std::shared_ptr<Drawing> drawing(ArvFakeCamera* camera, FramePattern pattern) {
  auto d = std::make_shared<Drawing>();
  d->pattern = std::move(pattern);
  d->sizer = arv_fake_camera_new("sizer");
  arv_fake_camera_set_fill_pattern(camera, fill, d.get());
  return d;
}

}  // namespace

struct SimulatedGigECamera::Impl {
  ArvGvFakeCamera* camera = nullptr;
  std::shared_ptr<Drawing> drawing;
};

SimulatedGigECamera::SimulatedGigECamera(const std::string& address, const std::string& serial,
                                         FramePattern pattern, double trigger_hz)
    : impl_(std::make_unique<Impl>()) {
  impl_->camera = arv_gv_fake_camera_new(address.c_str(), serial.c_str());
  if (impl_->camera && !arv_gv_fake_camera_is_running(impl_->camera)) {
    g_object_unref(impl_->camera);
    impl_->camera = nullptr;
  }
  if (impl_->camera) {
    ArvFakeCamera* fake = arv_gv_fake_camera_get_fake_camera(impl_->camera);
    arv_fake_camera_set_trigger_frequency(fake, trigger_hz);
    impl_->drawing = drawing(fake, std::move(pattern));
  }
  // Its threads answer discovery within a few milliseconds.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

SimulatedGigECamera::~SimulatedGigECamera() { stop(); }

bool SimulatedGigECamera::running() const { return impl_->camera != nullptr; }

void SimulatedGigECamera::stop() {
  if (impl_->camera) g_object_unref(impl_->camera);
  impl_->camera = nullptr;
}

size_t SimulatedGigECamera::frames_made() const {
  return impl_->drawing ? impl_->drawing->frames.load() : 0;
}

std::shared_ptr<void> draw_fake_camera(void* aravis_device, FramePattern pattern) {
  auto* device = static_cast<ArvDevice*>(aravis_device);
  if (!ARV_IS_FAKE_DEVICE(device)) return nullptr;
  return drawing(arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(device)), std::move(pattern));
}

}  // namespace rigcal::test

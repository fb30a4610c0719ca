#pragma once
// A GigE Vision or USB3 Vision camera through Aravis (doc/capture.md): the cameras the host sees,
// GenICam features set and read back, and a stream of frames. Aravis' types stay in camera.cpp.
#include <atomic>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/time.h"

namespace rigcal::capture {

struct CameraInfo {
  std::string id;  // what Aravis opens it by
  std::string vendor, model, serial, address, protocol;
  std::vector<std::string> pixel_formats;  // filled by list_cameras(true) and Camera::info()
};

// The cameras Aravis finds now (GigE Vision on every interface, USB3 Vision; the in-process fake
// too when `include_fake`), with their pixel formats when `open_each` (each camera opened once: a
// camera streaming to another host still lists, without its formats).
std::vector<CameraInfo> list_cameras(bool open_each, bool include_fake = false);
// Makes Aravis' in-process fake camera, "Fake_1", openable (for trying without a camera).
void enable_fake_interface();

// A feature as asked and as the camera took it.
struct FeatureResult {
  enum class Status { set, adjusted, absent, refused };
  std::string feature;  // the name used ("" when none of the alternatives exists)
  std::string asked, accepted;
  Status status = Status::set;
  bool required = false;
  std::string why;          // the setting it serves ("exposure_us: auto")
  std::string camera_says;  // Aravis' error when refused ("" otherwise)
};
// "127.0.0.1: Aravis Fake, serial GV01": what names a camera in messages.
std::string describe(const CameraInfo& info);
std::string_view to_string(FeatureResult::Status status);

// One frame as received. `image`: 8-bit or 16-bit one channel; 10/12/14-bit pixels are scaled
// to 16 bits (shifted up; their low bits zero), so that 16-bit readers see the full range.
struct Frame {
  cv::Mat image;
  uint64_t frame_id = 0;  // the camera's (GigE Vision: 16 bits, 1..65535, 0 never used)
  Time device_stamp{}, host_stamp{};
  std::string pixel_format;
};

// What a pop of the stream gave.
struct StreamEvent {
  enum class Kind { frame, incomplete, timeout } kind = Kind::timeout;
  Frame frame;            // kind == frame
  uint64_t frame_id = 0;  // kind == incomplete: the buffer's id
  std::string status;     // kind == incomplete: Aravis' buffer status
};

class Camera {
 public:
  // Opens the camera by Aravis id, serial number or address. Throws rigcal::Error naming `id` and
  // the cameras Aravis sees when it cannot.
  explicit Camera(const std::string& id);
  ~Camera();
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;

  const CameraInfo& info() const;
  // Whether the camera has the feature (implemented and available now).
  bool has(const std::string& feature) const;
  // The feature's value as text, nullopt when absent or unreadable.
  std::optional<std::string> get(const std::string& feature) const;
  // Booleans are given as true/false, yes/no, on/off or 1/0 (any case).
  // Sets the first of `alternatives` the camera has (GenICam names differ between standard
  // versions: ExposureTime and ExposureTimeAbs) to `value` and reads it back: set, adjusted (a
  // number the camera rounded by more than 0.1 %), refused (an error, or text read back other
  // than asked), absent (none of them). Never throws for the camera's answer: the caller decides
  // what a required setting's failure means.
  FeatureResult set(const std::vector<std::string>& alternatives, const std::string& value,
                    bool required, const std::string& why);
  // Executes a command feature (TriggerSoftware); false when the camera refuses it.
  bool execute(const std::string& command);

  // Streams with `buffers` buffers (continuous acquisition). Throws rigcal::Error naming the
  // camera.
  void start(int buffers);
  // The next buffer within `timeout_s`. Thread-safe against software_trigger() from another thread.
  StreamEvent next(double timeout_s);
  // False when the camera refused it.
  bool software_trigger();
  // Stops the acquisition (errors ignored: the camera may be gone); next() still gives the
  // buffers received before.
  void stop_acquisition();
  // Stops the acquisition and releases the stream.
  void stop();
  // True once Aravis reported the control connection lost (the camera gone or unplugged).
  bool lost() const;
  // The ArvDevice* underneath, for a caller that needs Aravis itself (the tests' simulators).
  void* aravis_device() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::capture

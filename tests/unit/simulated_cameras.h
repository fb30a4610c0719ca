#pragma once
// Aravis' camera simulators, in-process, for the capture tests: the GigE Vision simulator (the
// code of `arv-fake-gv-camera-0.8`, serving the real GigE Vision protocol on an address of the
// loopback interface) and the fake interface's camera "Fake_1" (not GigE; ignores software
// triggers). Each draws its images by Aravis' own pattern, or by a function given here.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "rigcal/core/time.h"

namespace rigcal::test {

// Fills `image` (8 or 16 bit, one channel, the camera's region) for the frame `frame_id` stamped
// `stamp` by the simulator.
using FramePattern = std::function<void(uint64_t frame_id, Time stamp, cv::Mat& image)>;

class SimulatedGigECamera {
 public:
  // Starts the simulator on `address` with serial `serial`; running() is false when the address
  // cannot be served (it is not on an interface, or another simulator holds it). In trigger mode
  // the simulator wakes at `trigger_hz`: it then makes a frame for a software trigger received
  // since (two in one period make one frame: Aravis' default, 25 Hz, merges triggers 40 ms
  // apart), and with TriggerSource Line0 it makes one every time (the hardware trigger's rate).
  SimulatedGigECamera(const std::string& address, const std::string& serial,
                      FramePattern pattern = {}, double trigger_hz = 1000);
  ~SimulatedGigECamera();
  bool running() const;
  // Stops serving at once (the camera disappears from the network).
  void stop();
  // Frames the simulator made (each filled once).
  size_t frames_made() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Draws the frames of the fake interface's camera opened as `aravis_device` (the ArvDevice* of
// rigcal::capture::Camera::aravis_device()) by `pattern`. The returned object holds what the
// drawing needs: keep it past the camera's end.
std::shared_ptr<void> draw_fake_camera(void* aravis_device, FramePattern pattern);

}  // namespace rigcal::test

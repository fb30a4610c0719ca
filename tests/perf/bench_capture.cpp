// `rigcal capture`'s recording of two cameras at the rig's rate (doc/capture.md): two of Aravis'
// GigE Vision simulators in this process (127.0.0.1 and 127.0.0.2 on the loopback), 1388 x 700
// BayerRG8 free running at 30 Hz (the simulator makes no frame on a hardware trigger; free
// running, both make theirs at the same instants, whole multiples of the period on the host's
// clock, as a shared trigger would), recorded through the GigE Vision stack and written as PNG.
// Counters: frames written, missing and incomplete a camera, the share of a core each camera's two
// threads took, the process's (the simulators' drawing and sending included).
#include <fmt/format.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>

#include "../unit/simulated_cameras.h"
#include "rigcal/capture/record.h"
#include "smoke.h"

namespace {

bool smoke = false;

double process_cpu_s() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The second simulator's address, added to the loopback when missing (root only).
std::unique_ptr<rigcal::test::SimulatedGigECamera> second_simulator(rigcal::test::FramePattern p) {
  auto camera = std::make_unique<rigcal::test::SimulatedGigECamera>("127.0.0.2", "GV02", p, 30);
  if (camera->running()) return camera;
  if (std::system("ip addr add 127.0.0.2/8 dev lo 2>/dev/null") != 0) return nullptr;
  camera = std::make_unique<rigcal::test::SimulatedGigECamera>("127.0.0.2", "GV02", p, 30);
  return camera->running() ? std::move(camera) : nullptr;
}

void BM_CaptureTwoCamerasAt30Hz(benchmark::State& state) {
  namespace fs = std::filesystem;
  const size_t frames = smoke ? 20 : 200;
  // A fixed texture a frame (a diagonal ramp shifted by the frame id), as a board image costs to
  // compress: not a constant image PNG would shrink to nothing.
  auto pattern = [](uint64_t id, rigcal::Time, cv::Mat& image) {
    for (int y = 0; y < image.rows; ++y) {
      uint8_t* row = image.ptr<uint8_t>(y);
      for (int x = 0; x < image.cols; ++x)
        row[x] = static_cast<uint8_t>((x * 7 + y * 3 + id) & 0xff);
    }
  };
  rigcal::test::SimulatedGigECamera left("127.0.0.1", "GV01", pattern, 30);
  auto right = second_simulator(pattern);
  if (!left.running() || !right) {
    state.SkipWithError(
        "needs 127.0.0.1 and 127.0.0.2 on the loopback for two simulators (as root: ip addr add "
        "127.0.0.2/8 dev lo)");
    return;
  }
  for (auto _ : state) {
    rigcal::capture::RecordOptions o;
    for (const auto& [folder, id] :
         {std::pair{"camera_left", "127.0.0.1"}, {"camera_right", "127.0.0.2"}}) {
      rigcal::io::CaptureCameraConfig c;
      c.folder = folder;
      c.id = id;
      c.region = std::array<int, 4>{0, 0, 1388, 700};
      c.trigger = "off";
      c.trigger_given = true;
      c.frame_rate_hz = 30;
      c.frame_rate_given = true;
      o.config.cameras.push_back(c);
    }
    o.out = fs::temp_directory_path() / fmt::format("rigcal_bench_capture_{}", ::getpid());
    fs::remove_all(o.out);
    o.frames = frames;
    const double cpu0 = process_cpu_s();
    const rigcal::capture::CaptureRun run = rigcal::capture::record(o);
    const double cpu = process_cpu_s() - cpu0;
    fs::remove_all(o.out);
    if (!run.error.empty()) state.SkipWithError(run.error.c_str());
    for (size_t k = 0; k < run.cameras.size(); ++k) {
      const auto& c = run.cameras[k];
      const std::string side = k == 0 ? "left_" : "right_";
      state.counters[side + "written"] = static_cast<double>(c.written);
      state.counters[side + "missing"] = static_cast<double>(c.missing);
      state.counters[side + "incomplete"] = static_cast<double>(c.incomplete);
      state.counters[side + "cpu_pct"] = 100 * (c.receive_cpu_s + c.write_cpu_s) / run.seconds;
      state.counters[side + "fps"] =
          c.stamps.size() > 1
              ? (c.stamps.size() - 1) / (c.stamps.back() - c.stamps.front()).seconds()
              : 0;
    }
    state.counters["pairs"] = static_cast<double>(run.pairs);
    state.counters["process_cpu_pct"] = 100 * cpu / run.seconds;
    state.counters["seconds"] = run.seconds;
  }
}
BENCHMARK(BM_CaptureTwoCamerasAt30Hz)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  smoke = rigcal::perf::take_smoke_flag(argc, argv);
  return rigcal::perf::run_benchmarks(argc, argv);
}

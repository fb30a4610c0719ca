// ROS1 bag files (io::BagSet through Debian's librosbag-storage, then the decoders and the
// conversion into a recording): the bytes as one .bag file. Bad bags must end in rigcal::Error;
// a conversion that fails leaves no recording and no temporary folder.
#include <system_error>

#include "fuzz_common.h"
#include "rigcal/io/bag.h"
#include "rigcal/io/convert.h"

static int fuzz_bag(const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  static const fs::path file = fuzz::scratch() / "input.bag";
  static const fs::path out = fuzz::scratch() / "recording";
  fuzz::write_file(file, fuzz::as_text(data, size));
  std::error_code ec;
  fs::remove_all(out, ec);
  bool converted = false;
  fuzz::expect_only_rigcal_errors([&] {
    io::ConvertOptions o;
    o.bags = {file};
    o.out = out;
    io::convert_recording(o);
    converted = true;
  });
  if (!converted && fs::exists(out)) fuzz::finding("a failed conversion left", out.string());
  for (const auto& e : fs::directory_iterator(fuzz::scratch())) {
    if (e.path().filename().string().find(".partial-") != std::string::npos)
      fuzz::finding("a temporary folder left", e.path().string());
  }
  return 0;
}
RIGCAL_FUZZ_TARGET(bag, fuzz_bag)

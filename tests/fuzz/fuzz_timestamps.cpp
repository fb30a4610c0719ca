// A topic folder's timestamps.txt (io::read_stamped_folder, vbr-devkit's layout): the bytes as
// timestamps.txt beside data/ holding three images; a folder read succeeds only with one stamp
// per file. Then the stamps read are paired with themselves, which must pair each with itself.
#include <string>

#include "fuzz_common.h"
#include "rigcal/io/image_sets.h"

static int fuzz_timestamps(const uint8_t* data, size_t size) {
  using namespace rigcal;
  namespace fs = std::filesystem;
  static const fs::path topic = [] {
    const fs::path t = fuzz::scratch() / "camera_left";
    for (const char* f : {"0000000000.png", "0000000001.png", "0000000002.png"})
      fuzz::write_file(t / "data" / f, "");
    return t;
  }();
  fuzz::write_file(topic / "timestamps.txt", fuzz::as_text(data, size));
  fuzz::expect_only_rigcal_errors([&] {
    const io::StampedFolder folder = io::read_stamped_folder(topic, ".png");
    if (folder.stamps.size() != folder.files.size())
      fuzz::finding("stamps and files differ in count", std::to_string(folder.stamps.size()));
    const auto pairs = io::pair_by_stamp(folder.stamps, folder.stamps, Time{0});
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (!pairs[i] || folder.stamps[*pairs[i]] != folder.stamps[i])
        fuzz::finding("a stamp not paired with an equal one", std::to_string(i));
    }
  });
  return 0;
}
RIGCAL_FUZZ_TARGET(timestamps, fuzz_timestamps)

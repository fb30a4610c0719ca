// Images (io::read_gray, a path): the bytes as one image file, read as it comes (the format from
// its first bytes) and, for a one-channel image, as a raw Bayer mosaic. Every outcome other than
// an image within the documented limits or rigcal::Error is a finding.
#include <string>

#include "fuzz_common.h"
#include "rigcal/io/image_io.h"

static int fuzz_image(const uint8_t* data, size_t size) {
  using namespace rigcal;
  static const std::filesystem::path file = fuzz::scratch() / "image";
  fuzz::write_file(file, fuzz::as_text(data, size));
  for (const io::Bayer bayer : {io::Bayer::none, io::Bayer::rggb}) {
    fuzz::expect_only_rigcal_errors([&] {
      const cv::Mat gray = io::read_gray(file, bayer);
      if (gray.type() != CV_8UC1 || gray.cols < io::kMinImageSide ||
          gray.rows < io::kMinImageSide || !io::within_image_limits(gray.cols, gray.rows)) {
        fuzz::finding("read_gray returned an image outside its contract",
                      std::to_string(gray.cols) + " x " + std::to_string(gray.rows) + " type " +
                          std::to_string(gray.type()));
      }
    });
  }
  return 0;
}
RIGCAL_FUZZ_TARGET(image, fuzz_image)

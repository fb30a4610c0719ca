#include "rigcal/io/image_io.h"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/core/error.h"

namespace rigcal::io {

Bayer bayer_from_string(std::string_view name) {
  if (name.empty()) return Bayer::none;
  for (Bayer b : {Bayer::rggb, Bayer::bggr, Bayer::grbg, Bayer::gbrg}) {
    if (name == to_string(b)) return b;
  }
  throw Error(fmt::format("Bayer pattern: expected rggb, bggr, grbg or gbrg, got '{}'", name));
}

std::string_view to_string(Bayer bayer) {
  switch (bayer) {
    case Bayer::rggb:
      return "rggb";
    case Bayer::bggr:
      return "bggr";
    case Bayer::grbg:
      return "grbg";
    case Bayer::gbrg:
      return "gbrg";
    case Bayer::none:
      break;
  }
  return "";
}

cv::Mat read_gray(const std::filesystem::path& path, Bayer bayer) {
  cv::Mat img = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (img.empty()) throw Error(fmt::format("{}: cannot read the image", path.string()));
  if (img.depth() == CV_16U) img.convertTo(img, CV_8U, 1.0 / 256);
  if (img.depth() != CV_8U)
    throw Error(fmt::format("{}: expected an 8- or 16-bit image", path.string()));
  cv::Mat gray;  // never img's buffer: demosaicing in place reads pixels it has overwritten
  if (bayer != Bayer::none) {
    if (img.channels() != 1) {
      throw Error(fmt::format("{}: a Bayer pattern ({}) was given but the image has {} channels",
                              path.string(), to_string(bayer), img.channels()));
    }
    // OpenCV names the pattern by the 2x2 block's second row.
    const int code = bayer == Bayer::rggb   ? cv::COLOR_BayerBG2GRAY
                     : bayer == Bayer::bggr ? cv::COLOR_BayerRG2GRAY
                     : bayer == Bayer::grbg ? cv::COLOR_BayerGB2GRAY
                                            : cv::COLOR_BayerGR2GRAY;
    cv::cvtColor(img, gray, code);
  } else if (img.channels() == 3) {
    cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  } else if (img.channels() == 4) {
    cv::cvtColor(img, gray, cv::COLOR_BGRA2GRAY);
  } else {
    gray = img;
  }
  return gray;
}

}  // namespace rigcal::io

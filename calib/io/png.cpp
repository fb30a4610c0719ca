#include "rigcal/io/png.h"

#include <opencv2/imgcodecs.hpp>

#include "rigcal/core/error.h"

namespace rigcal::io {

std::string encode_png(const cv::Mat& image) {
  std::vector<uchar> buffer;
  if (!cv::imencode(".png", image, buffer)) throw Error("PNG encoding failed");
  return std::string(buffer.begin(), buffer.end());
}

}  // namespace rigcal::io

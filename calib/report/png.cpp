#include "rigcal/report/png.h"

#include <opencv2/imgcodecs.hpp>

#include "rigcal/core/error.h"

namespace rigcal::report {

std::string encode_png(const cv::Mat& image) {
  std::vector<uchar> buffer;
  if (!cv::imencode(".png", image, buffer)) throw Error("PNG encoding failed");
  return std::string(buffer.begin(), buffer.end());
}

}  // namespace rigcal::report

#pragma once
// PNG bytes of an image, for writers that go through write_files_atomic.
#include <opencv2/core.hpp>
#include <string>

namespace rigcal::report {

// Throws rigcal::Error when OpenCV cannot encode the image.
std::string encode_png(const cv::Mat& image);

}  // namespace rigcal::report

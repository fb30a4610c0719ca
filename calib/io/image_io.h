#pragma once
// The one image reader of the calibration steps: PNG, JPEG, TIFF, PNM or BMP (8 or 16 bit; gray,
// BGR or BGRA; any other format refused) as 8-bit gray, raw Bayer mosaics (as VBR's cameras record
// them) demosaiced to gray.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string_view>

namespace rigcal::io {

// A raw mosaic's 2x2 pattern, named by its first row then second row (rggb: R G / G B).
enum class Bayer { none, rggb, bggr, grbg, gbrg };
// "" -> none; rggb | bggr | grbg | gbrg; anything else throws rigcal::Error listing the names.
Bayer bayer_from_string(std::string_view name);
std::string_view to_string(Bayer bayer);

// What read_gray accepts: a side of 16 to 32768 px and at most 100 Mpx, checked from the file's
// header (PNG, JPEG, TIFF, PNM, BMP) before anything is decoded.
inline constexpr long long kMinImageSide = 16;
inline constexpr long long kMaxImageSide = 32768;
inline constexpr long long kMaxImagePixels = 100'000'000;
// True when a width x height image is no larger than the limits above.
inline bool within_image_limits(long long width, long long height) {
  return width <= kMaxImageSide && height <= kMaxImageSide && width * height <= kMaxImagePixels;
}

// 8-bit gray. 16-bit images are scaled by 1/256; colour images converted with OpenCV's BGR
// weights; a Bayer image (one channel) demosaiced (edge-aware) to gray. Throws rigcal::Error
// naming the file when it cannot be read, is damaged (a PNG chunk's CRC, a JPEG's data), is outside
// the sizes above, or when a Bayer pattern is given for a colour image. libpng and libjpeg print
// nothing; OpenCV's warnings follow its log level (the CLI keeps errors only).
cv::Mat read_gray(const std::filesystem::path& path, Bayer bayer = Bayer::none);
// The same conversion of an image in memory (a camera's frame); `name` names it in errors.
cv::Mat to_gray(const cv::Mat& image, Bayer bayer, std::string_view name);

}  // namespace rigcal::io

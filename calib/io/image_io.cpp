#include "rigcal/io/image_io.h"

#include <fmt/format.h>
#include <zlib.h>

#include <cctype>
#include <csetjmp>
#include <cstdio>
#include <cstring>
// jpeglib.h needs <cstdio> first.
#include <jpeglib.h>
// After jpeglib.h: the message codes.
#include <jerror.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"

namespace rigcal::io {
namespace {

enum class ImageFormat { unknown, png, jpeg, pnm, bmp, tiff };
struct ImageHeader {
  ImageFormat format = ImageFormat::unknown;
  long long width = 0, height = 0;
  bool sized = false;  // width and height read from the header
};

uint32_t big_endian32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

// A classic TIFF's width and height (tags 256 and 257, SHORT or LONG) from its first directory;
// refused when the directory is not within the bytes or lacks either tag. What a decoder would
// allocate beyond the image is refused here too: samples wider than 16 bit or more than 4 a pixel
// (the reader keeps 8 and 16 bit), and tiles (cameras write strips; a tile's size is its own).
ImageHeader probe_tiff(const unsigned char* b, size_t n, const std::string& name) {
  ImageHeader h;
  h.format = ImageFormat::tiff;
  const bool little = b[0] == 'I';
  auto u16 = [&](size_t i) { return little ? b[i] | b[i + 1] << 8 : b[i] << 8 | b[i + 1]; };
  auto u32 = [&](size_t i) {
    return little ? uint32_t(u16(i)) | uint32_t(u16(i + 2)) << 16
                  : uint32_t(u16(i)) << 16 | uint32_t(u16(i + 2));
  };
  const size_t ifd = u32(4);
  const size_t count = ifd < 8 || ifd > n || n - ifd < 2 ? 0 : u16(ifd);
  bool width = false, height = false;
  for (size_t k = 0; k < count && ifd + 2 + 12 * (k + 1) <= n; ++k) {
    const size_t e = ifd + 2 + 12 * k;
    const int tag = u16(e), type = u16(e + 2);
    const uint32_t values = u32(e + 4);
    if (tag == 322 || tag == 323 || tag == 324 || tag == 325) {
      throw Error(
          fmt::format("{}: a tiled TIFF (rigcal reads TIFFs of strips, as cameras write)", name));
    }
    if (type != 3 && type != 4) continue;
    // The first value: inline when the values fit 4 bytes, else at the offset given.
    size_t at = e + 8;
    if (values * (type == 3 ? 2ull : 4ull) > 4) {
      at = u32(e + 8);
      if (at > n || n - at < 4) continue;
    }
    const long long v = type == 3 ? u16(at) : u32(at);
    if (tag == 256) h.width = v, width = values == 1;
    if (tag == 257) h.height = v, height = values == 1;
    if (tag == 258 && v > 16) {
      throw Error(fmt::format("{}: a TIFF of {}-bit samples (rigcal reads 8 or 16 bit)", name, v));
    }
    if (tag == 277 && v > 4) {
      throw Error(fmt::format("{}: a TIFF of {} samples a pixel (at most 4)", name, v));
    }
  }
  if (!width || !height) {
    throw Error(fmt::format("{}: TIFF without its width and height in the first directory", name));
  }
  h.sized = true;
  return h;
}

// The format and size an image file declares, read from its first bytes only, so a header that
// claims 100000 x 100000 px is refused before anything is allocated.
ImageHeader probe_image(std::string_view bytes, const std::string& name) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  ImageHeader h;
  if (n >= 8 && bytes.substr(0, 8) == "\x89PNG\r\n\x1a\n") {
    if (n >= 24 && bytes.substr(12, 4) == "IHDR")
      return {ImageFormat::png, big_endian32(b + 16), big_endian32(b + 20), true};
    h.format = ImageFormat::png;  // no header: check_png_chunks names what is missing
    return h;
  }
  if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) {
    h.format = ImageFormat::jpeg;
    // Markers up to the first start-of-frame (SOF0..SOF15 but DHT, JPG and DAC).
    for (size_t i = 2; i + 9 < n;) {
      if (b[i] != 0xFF) break;
      const unsigned char m = b[i + 1];
      if (m == 0xFF) {
        ++i;
        continue;
      }
      if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
        h.height = b[i + 5] << 8 | b[i + 6];
        h.width = b[i + 7] << 8 | b[i + 8];
        h.sized = true;
        break;
      }
      if (m == 0xD8 || (m >= 0xD0 && m <= 0xD7)) {
        i += 2;
        continue;
      }
      i += 2 + (size_t(b[i + 2]) << 8 | b[i + 3]);
    }
    return h;
  }
  if (n >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') {
    h.format = ImageFormat::pnm;
    // "P5 <width> <height> ...", comments from '#' to the line's end.
    long long v[2] = {0, 0};
    size_t i = 2;
    for (long long& x : v) {
      while (i < n && (std::isspace(b[i]) || b[i] == '#')) {
        if (b[i] == '#')
          while (i < n && b[i] != '\n') ++i;
        else
          ++i;
      }
      if (i >= n || !std::isdigit(b[i])) return h;
      for (; i < n && std::isdigit(b[i]) && x < (1LL << 40); ++i) x = x * 10 + (b[i] - '0');
    }
    h.width = v[0], h.height = v[1], h.sized = true;
    return h;
  }
  if (n >= 8 && (bytes.substr(0, 4) == std::string_view("II*\0", 4) ||
                 bytes.substr(0, 4) == std::string_view("MM\0*", 4))) {
    return probe_tiff(b, n, name);
  }
  if (n >= 26 && b[0] == 'B' && b[1] == 'M') {
    int32_t w, ht;
    std::memcpy(&w, b + 18, 4);
    std::memcpy(&ht, b + 22, 4);
    return {ImageFormat::bmp, std::abs(static_cast<long long>(w)),
            std::abs(static_cast<long long>(ht)), true};
  }
  return h;
}

void check_image_size(const ImageHeader& h, const std::string& name) {
  if (!within_image_limits(h.width, h.height)) {
    throw Error(
        fmt::format("{}: {} x {} px is larger than rigcal reads (at most {} px a side and {} Mpx)",
                    name, h.width, h.height, kMaxImageSide, kMaxImagePixels / 1000000));
  }
  if (h.width < kMinImageSide || h.height < kMinImageSide) {
    throw Error(fmt::format("{}: {} x {} px is too small to hold a target (at least {} px a side)",
                            name, h.width, h.height, kMinImageSide));
  }
}

// Every chunk of a PNG whole and its CRC right, up to IEND: libpng would otherwise print its
// own complaints to stderr before failing (or, for a damaged ancillary chunk, succeed).
void check_png_chunks(std::string_view bytes, const std::string& name) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  for (size_t i = 8;;) {
    if (i + 12 > bytes.size()) {
      throw Error(fmt::format("{}: PNG truncated at byte {} (no IEND chunk)", name, bytes.size()));
    }
    const uint32_t length = big_endian32(b + i);
    if (length > bytes.size() - i - 12) {
      throw Error(fmt::format("{}: PNG chunk at byte {} runs past the file's end", name, i));
    }
    const uint32_t crc = big_endian32(b + i + 8 + length);
    if (crc32(0, b + i + 4, length + 4) != crc) {
      throw Error(fmt::format("{}: PNG chunk '{}' at byte {} is damaged (CRC mismatch)", name,
                              printable(bytes.substr(i + 4, 4)), i));
    }
    if (bytes.substr(i + 4, 4) == "IEND") return;
    i += 12 + length;
  }
}

// libjpeg with its messages kept: a damaged JPEG is an error naming the file, never a warning
// on stderr and a half-grey image. Decodes as OpenCV's reader does (same library and defaults).
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  int warnings = 0;
  char message[JMSG_LENGTH_MAX] = {};
};

cv::Mat decode_jpeg(const std::string& bytes, const std::string& name) {
  jpeg_decompress_struct info;
  JpegError error;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = [](j_common_ptr c) {
    auto* e = reinterpret_cast<JpegError*>(c->err);
    c->err->format_message(c, e->message);
    std::longjmp(e->jump, 1);
  };
  error.manager.emit_message = [](j_common_ptr c, int level) {
    auto* e = reinterpret_cast<JpegError*>(c->err);
    // Extraneous bytes between markers damage no pixel; every other warning does.
    if (level >= 0 || c->err->msg_code == JWRN_EXTRANEOUS_DATA) return;
    if (e->warnings++ == 0) c->err->format_message(c, e->message);
  };
  cv::Mat img;
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    throw Error(fmt::format("{}: cannot read the JPEG ({})", name, printable(error.message)));
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  jpeg_read_header(&info, TRUE);
  const bool gray = info.num_components == 1;
  info.out_color_space = gray ? JCS_GRAYSCALE : JCS_EXT_BGR;
  jpeg_start_decompress(&info);
  img.create(static_cast<int>(info.output_height), static_cast<int>(info.output_width),
             gray ? CV_8UC1 : CV_8UC3);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = img.ptr<uchar>(static_cast<int>(info.output_scanline));
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  if (error.warnings > 0) {
    throw Error(fmt::format("{}: the JPEG is damaged ({})", name, printable(error.message)));
  }
  return img;
}

}  // namespace

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
  const std::string name = path.string();
  const std::string bytes = read_text_file(path);  // binary-safe
  const ImageHeader header = probe_image(bytes, name);
  // Only the formats probed above reach a decoder: OpenCV's other decoders (WebP, EXR, JPEG 2000,
  // HDR, Sun raster, PAM, PFM, GDAL's) are neither needed by a camera rig nor size-checked here.
  if (header.format == ImageFormat::unknown) {
    throw Error(fmt::format("{}: not an image rigcal reads (PNG, JPEG, TIFF, PNM or BMP)", name));
  }
  if (header.sized) check_image_size(header, name);
  cv::Mat img;
  if (header.format == ImageFormat::jpeg) {
    img = decode_jpeg(bytes, name);
  } else {
    if (header.format == ImageFormat::png) check_png_chunks(bytes, name);
    try {
      img = cv::imdecode(
          cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())),
          cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& e) {
      throw Error(fmt::format("{}: cannot read the image ({})", name, printable(e.err)));
    }
  }
  if (img.empty()) throw Error(fmt::format("{}: cannot read the image", name));
  if (!header.sized) check_image_size({header.format, img.cols, img.rows, true}, name);
  return to_gray(img, bayer, name);
}

cv::Mat to_gray(const cv::Mat& image, Bayer bayer, std::string_view name) {
  cv::Mat img = image;
  if (img.depth() == CV_16U) img.convertTo(img, CV_8U, 1.0 / 256);
  if (img.depth() != CV_8U) throw Error(fmt::format("{}: expected an 8- or 16-bit image", name));
  cv::Mat gray;  // never img's buffer: demosaicing in place reads pixels it has overwritten
  if (bayer != Bayer::none) {
    if (img.channels() != 1) {
      throw Error(fmt::format("{}: a Bayer pattern ({}) was given but the image has {} channels",
                              name, to_string(bayer), img.channels()));
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

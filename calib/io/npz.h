#pragma once
// numpy's array files, written without numpy: .npy (format version 1.0), .npz (a ZIP archive of
// .npy members, stored or deflated) and the base85 text Python's base64.b85encode gives, which
// mrcal uses to carry an .npz inside a .cameramodel (mrcal_cameramodel.h).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::io {

// One array: numpy's dtype text ('<f8', '<i4', '|b1', '<U17'), its shape (empty: a 0-d scalar)
// and its elements' bytes, little-endian in C order.
struct NpyArray {
  std::string descr;
  std::vector<size_t> shape;
  std::string data;
};

// float64 or int32 arrays of `shape` (the values' count must be its product), and the 0-d
// scalars mrcal reads back as a Python float, bool or str. Throws std::invalid_argument when the
// count does not match the shape.
NpyArray npy_array(const std::vector<double>& values, std::vector<size_t> shape);
NpyArray npy_array(const std::vector<int32_t>& values, std::vector<size_t> shape);
NpyArray npy_scalar(double value);
NpyArray npy_bool(bool value);
NpyArray npy_string(std::string_view ascii);  // '<U n', UTF-32LE; throws for non-ASCII text

// The .npy file: magic, version 1.0, the header dict padded as numpy 1.24 pads it (the whole
// header a multiple of 64 bytes, ending in '\n'), then the data.
std::string npy_bytes(const NpyArray& array);

enum class ZipMethod { stored, deflated };
struct ZipMember {
  std::string name;
  std::string data;
};
// A ZIP archive of the members in order (no zip64: every size under 4 GiB, at most 65535
// members; throws rigcal::Error otherwise). CRC-32 and raw deflate from zlib; timestamps
// 1980-01-01 00:00, so the same members give the same bytes.
std::string zip_bytes(const std::vector<ZipMember>& members, ZipMethod method);

// np.savez's archive: one member '<key>.npy' per named array.
struct NamedArray {
  std::string key;
  NpyArray array;
};
std::string npz_bytes(const std::vector<NamedArray>& arrays, ZipMethod method);

// Python's base64.b85encode: RFC 1924's alphabet, 4 bytes (big-endian) to 5 characters, the last
// partial group cut to its length + 1 characters; no padding, no line breaks.
std::string base85(std::string_view bytes);

}  // namespace rigcal::io

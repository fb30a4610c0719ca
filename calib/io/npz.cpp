#include "rigcal/io/npz.h"

#include <fmt/format.h>
#include <zlib.h>

#include <bit>
#include <limits>
#include <stdexcept>

#include "rigcal/core/error.h"

namespace rigcal::io {
namespace {

void put_le(std::string& out, uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out += static_cast<char>((value >> (8 * i)) & 0xff);
}

size_t element_count(const std::vector<size_t>& shape) {
  size_t n = 1;
  for (size_t s : shape) n *= s;
  return n;
}

void check_count(size_t values, const std::vector<size_t>& shape) {
  if (values != element_count(shape)) {
    throw std::invalid_argument(
        fmt::format("npy_array: {} values for a shape of {}", values, element_count(shape)));
  }
}

// numpy's repr of a shape: (), (n,), (a, b, ...).
std::string shape_text(const std::vector<size_t>& shape) {
  if (shape.size() == 1) return fmt::format("({},)", shape[0]);
  std::string s = "(";
  for (size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + ")";
}

std::string deflate_raw(const std::string& data) {
  z_stream z{};
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, static_cast<uLong>(data.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int status = ::deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw Error("zlib: deflate did not finish");
  return out;
}

}  // namespace

NpyArray npy_array(const std::vector<double>& values, std::vector<size_t> shape) {
  check_count(values.size(), shape);
  NpyArray a{"<f8", std::move(shape), {}};
  a.data.reserve(8 * values.size());
  for (double v : values) put_le(a.data, std::bit_cast<uint64_t>(v), 8);
  return a;
}

NpyArray npy_array(const std::vector<int32_t>& values, std::vector<size_t> shape) {
  check_count(values.size(), shape);
  NpyArray a{"<i4", std::move(shape), {}};
  a.data.reserve(4 * values.size());
  for (int32_t v : values) put_le(a.data, static_cast<uint32_t>(v), 4);
  return a;
}

NpyArray npy_scalar(double value) { return npy_array(std::vector<double>{value}, {}); }

NpyArray npy_bool(bool value) { return {"|b1", {}, std::string(1, value ? '\1' : '\0')}; }

NpyArray npy_string(std::string_view ascii) {
  // numpy has no '<U0': the empty string is '<U1' holding a NUL, as np.array('') is.
  NpyArray a{fmt::format("<U{}", std::max<size_t>(1, ascii.size())), {}, {}};
  for (char c : ascii) {
    if (static_cast<unsigned char>(c) > 0x7f)
      throw std::invalid_argument("npy_string: ASCII text only");
    put_le(a.data, static_cast<unsigned char>(c), 4);
  }
  if (ascii.empty()) put_le(a.data, 0, 4);
  return a;
}

std::string npy_bytes(const NpyArray& a) {
  std::string header = fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': {}, }}",
                                   a.descr, shape_text(a.shape));
  // numpy leaves room for the first axis to grow to 21 digits, then pads with spaces and a
  // final '\n' to a multiple of 64 bytes counted from the file's start (a whole 64 when aligned).
  if (!a.shape.empty()) header += std::string(21 - std::to_string(a.shape[0]).size(), ' ');
  const size_t preamble = 10;  // magic (6), version (2), header length (2)
  header += std::string(64 - (preamble + header.size() + 1) % 64, ' ') + '\n';
  if (header.size() > std::numeric_limits<uint16_t>::max())
    throw Error("npy: header over 64 kB (format 1.0)");
  std::string out = "\x93NUMPY\x01";
  out += '\0';
  put_le(out, header.size(), 2);
  return out + header + a.data;
}

std::string zip_bytes(const std::vector<ZipMember>& members, ZipMethod method) {
  constexpr uint64_t kMax32 = std::numeric_limits<uint32_t>::max();
  if (members.size() > std::numeric_limits<uint16_t>::max())
    throw Error(fmt::format("zip: {} members, at most 65535 without zip64", members.size()));
  const uint16_t method_id = method == ZipMethod::deflated ? 8 : 0;
  const uint16_t dos_time = 0, dos_date = (1 << 5) | 1;  // 1980-01-01 00:00
  std::string out, central;
  for (const ZipMember& m : members) {
    if (m.data.size() >= kMax32 || m.name.size() > std::numeric_limits<uint16_t>::max())
      throw Error(fmt::format("zip: member '{}' too large without zip64", m.name));
    const uint32_t crc = static_cast<uint32_t>(
        crc32(0, reinterpret_cast<const Bytef*>(m.data.data()), static_cast<uInt>(m.data.size())));
    const std::string payload = method == ZipMethod::deflated ? deflate_raw(m.data) : m.data;
    const uint64_t offset = out.size();
    if (offset >= kMax32) throw Error("zip: archive over 4 GiB without zip64");
    // The fields the local header and the central directory entry share.
    auto common = [&](std::string& b) {
      put_le(b, 20, 2);  // version needed to extract: 2.0
      put_le(b, 0, 2);   // flags
      put_le(b, method_id, 2);
      put_le(b, dos_time, 2);
      put_le(b, dos_date, 2);
      put_le(b, crc, 4);
      put_le(b, payload.size(), 4);
      put_le(b, m.data.size(), 4);
      put_le(b, m.name.size(), 2);
      put_le(b, 0, 2);  // extra field length
    };
    put_le(out, 0x04034b50, 4);
    common(out);
    out += m.name;
    out += payload;
    put_le(central, 0x02014b50, 4);
    put_le(central, 20, 2);  // version made by: 2.0, MS-DOS attributes
    common(central);
    put_le(central, 0, 2);  // comment length
    put_le(central, 0, 2);  // disk number
    put_le(central, 0, 2);  // internal attributes
    put_le(central, 0, 4);  // external attributes
    put_le(central, offset, 4);
    central += m.name;
  }
  const uint64_t central_offset = out.size();
  if (central_offset + central.size() >= kMax32)
    throw Error("zip: archive over 4 GiB without zip64");
  out += central;
  put_le(out, 0x06054b50, 4);
  put_le(out, 0, 2);  // this disk
  put_le(out, 0, 2);  // the central directory's disk
  put_le(out, members.size(), 2);
  put_le(out, members.size(), 2);
  put_le(out, central.size(), 4);
  put_le(out, central_offset, 4);
  put_le(out, 0, 2);  // comment length
  return out;
}

std::string npz_bytes(const std::vector<NamedArray>& arrays, ZipMethod method) {
  std::vector<ZipMember> members;
  members.reserve(arrays.size());
  for (const NamedArray& a : arrays) members.push_back({a.key + ".npy", npy_bytes(a.array)});
  return zip_bytes(members, method);
}

std::string base85(std::string_view bytes) {
  static constexpr char kAlphabet[] =
      "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz!#$%&()*+-;<=>?@^_`{|}~";
  std::string out;
  out.reserve((bytes.size() + 3) / 4 * 5);
  for (size_t i = 0; i < bytes.size(); i += 4) {
    const size_t n = std::min<size_t>(4, bytes.size() - i);
    uint32_t word = 0;
    for (size_t j = 0; j < 4; ++j)
      word = (word << 8) | (j < n ? static_cast<unsigned char>(bytes[i + j]) : 0u);
    char group[5];
    for (int j = 4; j >= 0; --j) {
      group[j] = kAlphabet[word % 85];
      word /= 85;
    }
    out.append(group, n + 1);
  }
  return out;
}

}  // namespace rigcal::io

#pragma once
// SHA-256 (FIPS 180-4) of bytes and files, as lowercase hex: the provenance of every input a
// calibration step read, and the key of the session pipeline's cache.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace rigcal {

class Sha256 {
 public:
  Sha256();
  void update(std::string_view bytes);
  std::string hex();  // finishes; the object is spent afterwards

 private:
  void block(const unsigned char* p);
  uint32_t h_[8];
  unsigned char buffer_[64];
  size_t buffered_ = 0;
  uint64_t length_ = 0;
};

std::string sha256_hex(std::string_view bytes);
// Streams the file; throws rigcal::Error naming it when it cannot be read.
std::string sha256_file(const std::filesystem::path& path);

}  // namespace rigcal

#pragma once
// SHA-256 (FIPS 180-4) of bytes and files, as lowercase hex: the provenance of every input a
// calibration step read, and the key of the session pipeline's cache. Computed by OpenSSL's
// libcrypto, which uses the CPU's SHA instructions where it has them (a cached rerun of the
// demo's session, 1.2 GB hashed, 4 times faster than with the portable code this replaced:
// doc/performance.md).
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace rigcal {

class Sha256 {
 public:
  Sha256();  // throws rigcal::Error when libcrypto has no SHA-256 (never on Debian 12)
  void update(std::string_view bytes);
  std::string hex();  // finishes; the object is spent afterwards

 private:
  struct Free {
    void operator()(evp_md_ctx_st* context) const;
  };
  std::unique_ptr<evp_md_ctx_st, Free> context_;
};

std::string sha256_hex(std::string_view bytes);
// Streams the file; throws rigcal::Error naming it when it cannot be read.
std::string sha256_file(const std::filesystem::path& path);

}  // namespace rigcal

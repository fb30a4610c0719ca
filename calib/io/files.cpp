#include "rigcal/io/files.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "rigcal/core/error.h"
#include "rigcal/core/memory.h"

namespace rigcal::io {

namespace fs = std::filesystem;

namespace {

void refuse_non_files(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    throw Error(fmt::format("{}: is a folder, expected a file", path.string()));
  }
  // A pipe would block until a writer comes and has no size to read by: refused, as are sockets.
  if (const fs::file_type t = fs::status(path, ec).type();
      t == fs::file_type::fifo || t == fs::file_type::socket) {
    throw Error(fmt::format("{}: a pipe or socket, expected a file", path.string()));
  }
}

}  // namespace

void read_text_blocks(const fs::path& path,
                      const std::function<void(std::string_view block)>& visit,
                      size_t block_bytes) {
  refuse_non_files(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error(fmt::format("{}: cannot open: {}", path.string(), std::strerror(errno)));
  }
  // One buffer reused: the lines cut at a block's end move to its front before the next read.
  UninitialisedVector<char> buffer(block_bytes + 1);  // read into, not zeroed first
  size_t kept = 0;
  while (true) {
    in.read(buffer.data() + kept, static_cast<std::streamsize>(buffer.size() - kept));
    if (in.bad()) throw Error(fmt::format("{}: read error", path.string()));
    const size_t filled = kept + static_cast<size_t>(in.gcount());
    const bool end = in.eof() || in.gcount() == 0;
    const std::string_view data(buffer.data(), filled);
    size_t cut = end ? filled : data.rfind('\n');
    if (cut == std::string_view::npos) {  // a line longer than the buffer: grow it
      buffer.resize(buffer.size() * 2);
      kept = filled;
      continue;
    }
    if (!end) ++cut;  // the block keeps its last '\n'
    visit(data.substr(0, cut));
    if (end) return;
    kept = filled - cut;
    std::memmove(buffer.data(), buffer.data() + cut, kept);
  }
}

size_t file_size_or_zero(const fs::path& path) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return ec ? 0 : static_cast<size_t>(size);
}

std::string read_text_file(const fs::path& path, size_t max_bytes) {
  refuse_non_files(path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    throw Error(fmt::format("{}: cannot open: {}", path.string(), std::strerror(errno)));
  }
  // One allocation of the file's size (large trajectories are hundreds of MB).
  const std::streamoff size = in.tellg();
  if (size > 0 && static_cast<size_t>(size) > max_bytes) {
    throw Error(fmt::format("{}: {} bytes, over the limit of {} bytes for this kind of file",
                            path.string(), size, max_bytes));
  }
  std::string text(size > 0 ? static_cast<size_t>(size) : 0, '\0');
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad() || in.gcount() != static_cast<std::streamsize>(text.size())) {
    throw Error(fmt::format("{}: read error", path.string()));
  }
  return text;
}

namespace {

// A temporary path beside `path` (same folder, so that the rename is atomic).
fs::path temporary_sibling(const fs::path& path) {
  static std::atomic<int> counter{0};
  fs::path tmp = path;
  tmp += fmt::format(".tmp-{}-{}{}", ::getpid(), counter++, path.extension().string());
  return tmp;
}

}  // namespace

void write_files_atomic(const std::vector<OutputFile>& files) {
  std::vector<fs::path> temps;
  auto cleanup = [&] {
    std::error_code ec;
    for (const fs::path& t : temps) fs::remove(t, ec);
  };
  try {
    for (const OutputFile& f : files) {
      const fs::path parent = f.path.has_parent_path() ? f.path.parent_path() : fs::path(".");
      std::error_code ec;
      fs::create_directories(parent, ec);
      if (ec) {
        throw Error(fmt::format("{}: cannot create the folder: {}", parent.string(), ec.message()));
      }
      if (fs::is_directory(f.path, ec)) {
        throw Error(fmt::format("{}: is a folder, expected a file path", f.path.string()));
      }
      temps.push_back(temporary_sibling(f.path));
      std::ofstream out(temps.back(), std::ios::binary | std::ios::trunc);
      if (!out) {
        throw Error(fmt::format("{}: cannot write: {}", f.path.string(), std::strerror(errno)));
      }
      out << f.content;
      out.flush();
      if (!out) throw Error(fmt::format("{}: write failed (disk full?)", f.path.string()));
    }
    for (size_t i = 0; i < files.size(); ++i) {
      std::error_code ec;
      fs::rename(temps[i], files[i].path, ec);
      if (ec) {
        throw Error(fmt::format("{}: cannot rename the finished file into place: {}",
                                files[i].path.string(), ec.message()));
      }
    }
  } catch (...) {
    cleanup();
    throw;
  }
}

void write_file_atomic(const fs::path& path, const std::string& content) {
  write_files_atomic({{path, content}});
}

namespace {
// A path resolved as far as it can be (a link loop or a missing folder leaves it as written,
// made absolute).
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(p, ec);
  return ec ? fs::absolute(p, ec).lexically_normal() : r;
}
}  // namespace

void refuse_outputs_over_inputs(const std::vector<OutputFile>& outputs,
                                const std::vector<std::pair<std::string, fs::path>>& inputs) {
  for (const OutputFile& out : outputs) {
    if (out.path.empty()) continue;
    for (const auto& [what, in] : inputs) {
      if (in.empty()) continue;
      std::error_code ec, ec_in;
      const bool same = fs::exists(out.path, ec) && fs::exists(in, ec_in) && !ec && !ec_in
                            ? fs::equivalent(out.path, in, ec) && !ec
                            : resolved(out.path) == resolved(in);
      if (same) {
        throw Error(
            fmt::format("{}: is an input ({}); the output would destroy it: choose "
                        "another output",
                        out.path.string(), what));
      }
    }
  }
}

void refuse_replacing_inputs(const fs::path& folder,
                             const std::vector<std::pair<std::string, fs::path>>& inputs) {
  std::error_code ec;
  // a lies at or below b.
  auto within = [](const fs::path& a, const fs::path& b) {
    auto [ia, ib] = std::mismatch(a.begin(), a.end(), b.begin(), b.end());
    return ib == b.end() || (std::next(ib) == b.end() && ib->empty());
  };
  const fs::path f = resolved(folder);
  if (within(resolved(fs::current_path(ec)), f)) {
    throw Error(
        fmt::format("{}: holds the current folder; replacing it would remove it: choose "
                    "another output folder",
                    folder.string()));
  }
  for (const auto& [what, in] : inputs) {
    if (!in.empty() && within(resolved(in), f)) {
      throw Error(
          fmt::format("{}: holds an input ({}, {}); replacing it would remove it: choose "
                      "another output folder",
                      folder.string(), what, in.string()));
    }
  }
}

FolderLock::FolderLock(const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) {
    throw Error(fmt::format("{}: cannot open the output folder: {}", folder.string(),
                            std::strerror(errno)));
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw Error(fmt::format(
        "{}: another rigcal run is writing this folder; wait for it to end or choose another "
        "output folder",
        folder.string()));
  }
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace rigcal::io

#pragma once
// Whole-file reading and all-or-nothing writing. Every output of rigcal goes through
// write_files_atomic: each file is written to a temporary name beside its destination, flushed,
// and renamed only when all of them were written, so a failed run leaves no half-written output.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rigcal::io {

// Throws rigcal::Error naming the path when the file cannot be read, or when it is larger than
// `max_bytes` (a documented limit of the format being read: kMaxYamlBytes for YAML).
std::string read_text_file(const std::filesystem::path& path, size_t max_bytes = SIZE_MAX);

// The file in blocks of about `block_bytes`, each ending at a line end ('\n') except the last:
// what a reader of lines needs, without holding the whole file. Same refusals as read_text_file.
void read_text_blocks(const std::filesystem::path& path,
                      const std::function<void(std::string_view block)>& visit,
                      size_t block_bytes = size_t{8} << 20);
// The file's size in bytes, 0 when it cannot be told.
size_t file_size_or_zero(const std::filesystem::path& path);

struct OutputFile {
  std::filesystem::path path;
  std::string content;
};
// Creates missing parent folders. On failure nothing is renamed and the temporaries are removed.
void write_files_atomic(const std::vector<OutputFile>& files);
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

// Throws rigcal::Error when an output is one of the inputs (the same file, links resolved): a
// command never writes over what it reads. `inputs` holds (what, path) pairs for the message.
void refuse_outputs_over_inputs(
    const std::vector<OutputFile>& outputs,
    const std::vector<std::pair<std::string, std::filesystem::path>>& inputs);

// Throws rigcal::Error when replacing `folder` (removing what it holds) would remove an input or
// the working folder: `folder` is the current folder or one above it, or holds one of `inputs`.
void refuse_replacing_inputs(
    const std::filesystem::path& folder,
    const std::vector<std::pair<std::string, std::filesystem::path>>& inputs);

// An exclusive claim on an output folder for one run (flock on the folder itself, so nothing is
// left behind; released when the object ends, or the process does). Two runs writing the same
// folder at once would leave a mixture of their files: the second is refused with a
// rigcal::Error naming the folder. Creates the folder when missing.
class FolderLock {
 public:
  explicit FolderLock(const std::filesystem::path& folder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace rigcal::io

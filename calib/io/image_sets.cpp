#include "rigcal/io/image_sets.h"

#include <fmt/format.h>
#include <glob.h>

#include <algorithm>
#include <map>

#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"
#include "rigcal/io/files.h"

namespace rigcal::io {

namespace fs = std::filesystem;

std::vector<std::string> glob_files(const std::string& pattern) {
  glob_t g{};
  std::vector<std::string> out;
  if (::glob(pattern.c_str(), 0, nullptr, &g) == 0) {
    for (size_t i = 0; i < g.gl_pathc; ++i) out.emplace_back(g.gl_pathv[i]);
  }
  globfree(&g);
  std::sort(out.begin(), out.end());
  return out;
}

std::optional<long> frame_number(const std::string& path) {
  const std::string stem = fs::path(path).stem().string();
  size_t end = stem.find_last_of("0123456789");
  if (end == std::string::npos) return std::nullopt;
  size_t start = end;
  while (start > 0 && std::isdigit(static_cast<unsigned char>(stem[start - 1]))) --start;
  return std::stol(stem.substr(start, end - start + 1));
}

ImageSet pair_by_frame_number(
    const std::vector<std::pair<std::string, std::vector<std::string>>>& cams) {
  ImageSet in;
  std::map<long, std::vector<std::string>> frames;
  for (size_t c = 0; c < cams.size(); ++c) {
    in.names.push_back(cams[c].first);
    std::map<long, std::string> seen;
    for (const std::string& f : cams[c].second) {
      const std::optional<long> n = frame_number(f);
      if (!n)
        throw Error(
            fmt::format("{}: no frame number in the file name; images are paired by it", f));
      if (seen.count(*n))
        throw Error(fmt::format("camera {}: {} and {} have the same frame number {}", cams[c].first,
                                seen[*n], f, *n));
      seen[*n] = f;
      auto& row = frames[*n];
      row.resize(cams.size());
      row[c] = f;
    }
  }
  in.files.assign(cams.size(), {});
  size_t singles = 0;
  for (const auto& [n, row] : frames) {
    for (size_t c = 0; c < cams.size(); ++c) in.files[c].push_back(c < row.size() ? row[c] : "");
    singles += std::count(row.begin(), row.end(), std::string()) > 0 || row.size() < cams.size();
  }
  if (cams.size() > 1 && singles)
    in.notes.push_back(fmt::format("{} frames have an image from one camera only", singles));
  return in;
}

StampedFolder read_stamped_folder(const fs::path& folder, const std::string& extension) {
  return read_stamped_folder(folder, extension, "data", "timestamps.txt");
}

StampedFolder read_stamped_folder(const fs::path& folder, const std::string& extension,
                                  const std::string& files, const std::string& stamps_file) {
  StampedFolder out;
  out.files = glob_files((folder / files / ("*" + extension)).string());
  const fs::path stamps = folder / stamps_file;
  const std::string text = read_text_file(stamps);
  for (const TextLine& line : data_lines(text, nullptr)) {
    Time t;
    try {
      t = parse_time(line.text);
    } catch (const Error& e) {
      fail_at(stamps.string(), line.number, "", e.what());
    }
    // The files pair with the stamps in order, so the stamps must be in order too.
    if (!out.stamps.empty() && t <= out.stamps.back()) {
      fail_at(stamps.string(), line.number, "",
              fmt::format("stamp {} is not after the previous line's ({}); a topic's frames are "
                          "stamped in increasing order",
                          to_seconds_text(t), to_seconds_text(out.stamps.back())));
    }
    out.stamps.push_back(t);
  }
  if (out.stamps.size() != out.files.size()) {
    throw Error(fmt::format("{}: {} stamps in {} for {} {} files in {}/", folder.string(),
                            out.stamps.size(), stamps_file, out.files.size(), extension, files));
  }
  return out;
}

std::vector<std::optional<size_t>> pair_by_stamp(const std::vector<Time>& a,
                                                 const std::vector<Time>& b, Time tolerance) {
  std::vector<std::optional<size_t>> out(a.size());
  std::vector<char> used(b.size(), 0);
  for (size_t i = 0; i < a.size(); ++i) {
    size_t best = 0;
    int64_t best_d = INT64_MAX;
    for (size_t j = 0; j < b.size(); ++j) {
      const int64_t d = std::abs((b[j] - a[i]).ns);
      if (d < best_d) best_d = d, best = j;
    }
    if (best_d <= tolerance.ns && !used[best]) {
      used[best] = 1;
      out[i] = best;
    }
  }
  return out;
}

ImageSet read_session_images(const fs::path& dir) {
  std::vector<std::pair<std::string, StampedFolder>> cams;
  for (const auto& [folder, name] :
       {std::pair{"camera_left", "cam_l"}, std::pair{"camera_right", "cam_r"}}) {
    if (fs::exists(dir / folder))
      cams.emplace_back(name, read_stamped_folder(dir / folder, ".png"));
  }
  if (cams.empty())
    throw Error(fmt::format("{}: no camera_left or camera_right folder", dir.string()));
  ImageSet in;
  for (const auto& c : cams) in.names.push_back(c.first);
  in.files.assign(cams.size(), {});
  if (cams.size() == 1) {
    in.files[0] = cams[0].second.files;
    return in;
  }
  // Pair by stamp: the nearest right image within 5 ms of each left one.
  const std::vector<std::optional<size_t>> right =
      pair_by_stamp(cams[0].second.stamps, cams[1].second.stamps, Time::from_ns(5'000'000));
  for (size_t i = 0; i < right.size(); ++i) {
    in.files[0].push_back(cams[0].second.files[i]);
    in.files[1].push_back(right[i] ? cams[1].second.files[*right[i]] : "");
  }
  return in;
}

}  // namespace rigcal::io

#pragma once
// An HTML report loaded in a real browser: headless Chromium (Debian's `chromium`), its DOM
// after loading, a screenshot, and its console's errors.
#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_run.h"

namespace rigcal::testing {

struct BrowserLoad {
  bool ran = false;
  std::string dom, log;  // the DOM after loading; Chromium's log (stderr)
  size_t screenshot_bytes = 0;
};

inline bool have_chromium() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

// The page at `html` loaded twice: its DOM, then a 1200 x 2400 screenshot into `png`.
inline BrowserLoad load_in_browser(const std::filesystem::path& html,
                                   const std::filesystem::path& png) {
  namespace fs = std::filesystem;
  BrowserLoad b;
  const fs::path dir = png.parent_path();
  const std::string flags =
      "--headless --no-sandbox --disable-gpu --enable-logging=stderr --v=0 --user-data-dir=" +
      (dir / "chromium_profile").string();
  const std::string url = "file://" + fs::absolute(html).string();
  const int dom =
      std::system(fmt::format("chromium {} --dump-dom {} > {} 2> {}", flags, url,
                              (dir / "dom.html").string(), (dir / "chromium_dom.log").string())
                      .c_str());
  const int shot =
      std::system(fmt::format("chromium {} --screenshot={} --window-size=1200,2400 {} "
                              "> /dev/null 2> {}",
                              flags, png.string(), url, (dir / "chromium_shot.log").string())
                      .c_str());
  b.ran = dom == 0 && shot == 0;
  b.dom = slurp(dir / "dom.html");
  b.log = slurp(dir / "chromium_dom.log") + slurp(dir / "chromium_shot.log");
  if (fs::exists(png)) b.screenshot_bytes = fs::file_size(png);
  return b;
}

// The page's console messages in Chromium's log (every level shows as INFO:CONSOLE; a report
// has no script, so any message is an error: an uncaught exception, a resource refused).
inline std::string console_messages(const std::string& log) {
  std::string out;
  for (size_t at = log.find(":CONSOLE"); at != std::string::npos;
       at = log.find(":CONSOLE", at + 1)) {
    const size_t start = log.rfind('\n', at), end = log.find('\n', at);
    out += log.substr(start == std::string::npos ? 0 : start + 1,
                      (end == std::string::npos ? log.size() : end) -
                          (start == std::string::npos ? 0 : start + 1)) +
           "\n";
  }
  return out;
}

}  // namespace rigcal::testing

// rigcal report DIR: a report's page rendered again from what its run stored (doc/report.md).
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/session/report_html.h"

namespace rigcal::cli {

void add_report(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Render DIR/report.html again from the JSON and figures a run stored in DIR (rigcal\n"
      "calibrate's OUT/reports/, rigcal check's check.json, rigcal diff's diff.json), as mrcal's\n"
      "tools render from stored results: a\n"
      "report can be re-read with a newer rigcal without re-running. One self-contained file,\n"
      "no script, its figures inline.");
  cmd->add_option("dir", *dir,
                  "a calibrate --out folder, or a check --report or diff --report folder")
      ->required();
  cmd->callback([dir] {
    const io::OutputFile page = session::render_report(*dir);
    io::write_file_atomic(page.path, page.content);
    fmt::print("wrote {}\n", page.path.string());
  });
}

}  // namespace rigcal::cli

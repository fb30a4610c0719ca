// rigcal target print T.yaml --out T.pdf: a printable target at exact scale.
#include <fmt/format.h>

#include <memory>

#include "cli.h"
#include "rigcal/io/files.h"
#include "rigcal/io/target_pdf.h"
#include "rigcal/io/target_yaml.h"

namespace rigcal::cli {

void add_target_print(CLI::App& target) {
  auto file = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = target.add_subcommand(
      "print",
      "Write a printable PDF of a target at exact physical scale, with its name, dimensions\n"
      "and a 100 mm scale bar in the margin. Print at 100 % and measure the bar.");
  cmd->add_option("file", *file, "target YAML (targets/*.yaml)")->required();
  cmd->add_option("--out", *out, "output PDF")->required();
  cmd->callback([file, out] {
    const camera::Target t = io::read_target_file(*file);
    const std::vector<io::OutputFile> files{{*out, io::target_pdf(t)}};
    io::refuse_outputs_over_inputs(files, {{"the target", *file}});
    io::write_files_atomic(files);
    const camera::Outline o = camera::outline(t);
    fmt::print("wrote {}: {} on a {:.1f} x {:.1f} mm board\n", *out, t.name, 1000 * o.width(),
               1000 * o.height());
  });
}

}  // namespace rigcal::cli

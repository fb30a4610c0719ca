#pragma once
#include <string>

namespace rigcal {

// "rigcal 0.1.0 (<git describe>)": shown by --version and written into every file and report.
std::string version_string();

}  // namespace rigcal

#pragma once
// A printable PDF of a target at exact physical scale (cairo), with the target's name,
// dimensions and a 100 mm scale bar in the margin (doc/targets.md).
#include <string>

#include "rigcal/camera/target.h"

namespace rigcal::io {

// The PDF's bytes. The page is the board plus a 20 mm margin for the text.
std::string target_pdf(const camera::Target& target);

}  // namespace rigcal::io

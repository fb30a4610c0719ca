#include "rigcal/core/version.h"

#include "rigcal_version.h"

namespace rigcal {

std::string version_string() {
  return std::string("rigcal ") + RIGCAL_VERSION + " (" + RIGCAL_GIT_REVISION + ")";
}

}  // namespace rigcal

#include "server/http/build_info.h"

// server/CMakeLists.txt defines these for this file alone; the fallbacks keep
// a build by other means compiling.
#ifndef SKYFARM_GIT_COMMIT
#define SKYFARM_GIT_COMMIT "unknown"
#endif
#ifndef SKYFARM_COMPILER
#define SKYFARM_COMPILER "unknown"
#endif
#ifndef SKYFARM_BUILD_TYPE
#define SKYFARM_BUILD_TYPE "none"
#endif

namespace skyfarm::server {

const BuildInfo& build_info() {
  static const BuildInfo info{SKYFARM_VERSION, SKYFARM_GIT_COMMIT, SKYFARM_COMPILER, SKYFARM_BUILD_TYPE};
  return info;
}

}  // namespace skyfarm::server

// What this binary was built from, for /metrics' skyfarm_build_info.
//   version     the project version (CMake's project(VERSION))
//   git_commit  the short commit hash at configure time, "unknown" without git
//   compiler    "<CMAKE_CXX_COMPILER_ID> <version>", e.g. "GNU 12.2.0"
//   build_type  CMAKE_BUILD_TYPE, "none" when unset
#pragma once
#include <string_view>

namespace skyfarm::server {

struct BuildInfo {
  std::string_view version;
  std::string_view git_commit;
  std::string_view compiler;
  std::string_view build_type;
};

const BuildInfo& build_info();

}  // namespace skyfarm::server

// Test support: the source tree's example requests and reading files whole.
#pragma once
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace skyfarm::testing {

// api/examples/ of the source tree.
inline const std::filesystem::path kExamples = std::filesystem::path(SKYFARM_SOURCE_DIR) / "api" / "examples";

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace skyfarm::testing

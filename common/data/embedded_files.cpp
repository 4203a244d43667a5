#include "common/data/embedded_files.h"

#include <cstddef>
#include <stdexcept>

namespace skyfarm::embedded {
struct Entry { const char* name; const char* data; std::size_t size; };
extern const Entry kEntries[];
extern const std::size_t kEntryCount;
}  // namespace skyfarm::embedded

namespace skyfarm {

std::string_view embedded_file(std::string_view name) {
  for (std::size_t i = 0; i < embedded::kEntryCount; ++i) {
    const auto& e = embedded::kEntries[i];
    if (name == e.name) return {e.data, e.size};
  }
  throw std::out_of_range("data table not embedded: " + std::string(name));
}

std::vector<std::string> embedded_file_names() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < embedded::kEntryCount; ++i) names.emplace_back(embedded::kEntries[i].name);
  return names;
}

}  // namespace skyfarm

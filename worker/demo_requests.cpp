#include "worker/demo_requests.h"

#include <cstddef>
#include <string_view>

// Generated as embedded_demos.cpp from api/examples/demo_*.json (worker/CMakeLists.txt).
namespace skyfarm::embedded_demos {
struct Entry { const char* name; const char* data; std::size_t size; };
extern const Entry kEntries[];
extern const std::size_t kEntryCount;
}  // namespace skyfarm::embedded_demos

namespace skyfarm {

// api/examples/demo_<name>.json, embedded: the files the README's run command
// also posts to the farm, so both render the same requests.
const std::vector<DemoRequest>& demo_requests() {
  static const std::vector<DemoRequest> demos = [] {
    std::vector<DemoRequest> out;
    for (std::size_t i = 0; i < embedded_demos::kEntryCount; ++i) {
      const auto& e = embedded_demos::kEntries[i];
      std::string_view name(e.name);
      name.remove_prefix(std::string_view("demo_").size());
      name.remove_suffix(std::string_view(".json").size());
      out.push_back({std::string(name), std::string(e.data, e.size)});
    }
    return out;
  }();
  return demos;
}

}  // namespace skyfarm

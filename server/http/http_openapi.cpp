#include "server/http/http_openapi.h"

#include <cstddef>

// Generated as embedded_openapi.cpp (cmake/embed_files.cmake).
namespace skyfarm::embedded_api {
struct Entry { const char* name; const char* data; std::size_t size; };
extern const Entry kEntries[];
extern const std::size_t kEntryCount;
}  // namespace skyfarm::embedded_api

namespace skyfarm::server {

std::string_view openapi_yaml() {
  for (std::size_t i = 0; i < embedded_api::kEntryCount; ++i) {
    const auto& e = embedded_api::kEntries[i];
    if (std::string_view(e.name) == "openapi.yaml") return {e.data, e.size};
  }
  return {};
}

}  // namespace skyfarm::server

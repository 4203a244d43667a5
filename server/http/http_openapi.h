// api/openapi.yaml as embedded in the binary at build time
// (cmake/EmbedData.cmake skyfarm_embed_files), served at GET /v1/openapi.yaml.
#pragma once
#include <string_view>

namespace skyfarm::server {

inline constexpr const char* kOpenApiContentType = "application/yaml";

// The document's text; empty if it was not embedded (a build error).
std::string_view openapi_yaml();

}  // namespace skyfarm::server

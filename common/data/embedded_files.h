// Access to the data tables embedded at build time (cmake/EmbedData.cmake).
#pragma once
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm {

// The text of data/<name> as embedded in the binary.  Throws std::out_of_range
// naming the file when it was not embedded.
std::string_view embedded_file(std::string_view name);

// Names of all embedded files, for diagnostics.
std::vector<std::string> embedded_file_names();

}  // namespace skyfarm

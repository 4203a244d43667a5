// std::invalid_argument with a message streamed from its parts, for the LUT
// builders' parameter checks (and no `"literal" + std::string`, on which
// GCC 12 reports a false -Wrestrict).
#pragma once
#include <sstream>
#include <stdexcept>

namespace skyfarm::lut {

template <class... Parts>
std::invalid_argument invalid_argument(const Parts&... parts) {
  std::ostringstream s;
  (s << ... << parts);
  return std::invalid_argument(s.str());
}

}  // namespace skyfarm::lut

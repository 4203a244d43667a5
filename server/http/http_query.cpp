#include "server/http/http_query.h"

#include <httplib.h>

#include <string>

#include "server/http/http_checks.h"
#include "server/http/http_problem.h"

namespace skyfarm::server {
namespace {

// An optional query parameter given at most once, an integer in [lo, hi].
std::uint64_t query_number(const httplib::Request& req, const char* name, std::uint64_t fallback, std::uint64_t lo,
                           std::uint64_t hi) {
  const std::size_t count = req.get_param_value_count(name);
  if (count == 0) return fallback;
  if (count > 1) throw invalid_parameter(name, "must be given once", std::to_string(count) + " values");
  const std::string text = req.get_param_value(name);
  const auto value = parse_decimal(text, hi);
  if (!value || *value < lo)
    throw invalid_parameter(name, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
                            quote_text(text));
  return *value;
}

}  // namespace

Page page_of(const httplib::Request& req) {
  return {query_number(req, "offset", 0, 0, kMaxListOffset),
          query_number(req, "limit", kDefaultListLimit, 1, kMaxListLimit)};
}

}  // namespace skyfarm::server

// HTTP requests for /metrics, by route TEMPLATE (api/openapi.yaml's
// `/v1/renders/{id}`, never the raw path with its id), method and status:
//   skyfarm_http_requests_total{route,method,code}          counter
//   skyfarm_http_request_duration_seconds{route,method,code_class}
//                                                            histogram
// Parameters
//   routes  the routes the server answers (RouteRegistrar::added()); a path
//           none of them matches is counted as route="other", a method
//           outside GET, HEAD, POST, PUT, PATCH, DELETE, OPTIONS as
//           method="other", so that no client can grow the series without
//           bound.  code is the status (100-599), code_class "2xx" etc.
// The duration runs from routing (the request line and headers read) to the
// response written, event streams included (their route tells them apart).
#pragma once
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "common/core/metrics_histogram.h"
#include "server/http/http_routes.h"

namespace skyfarm::server {

// Whether `path` matches the OpenAPI path template: literal text as is, each
// `{name}` one or more characters other than '/' (as route_pattern()).
bool path_matches_template(std::string_view path_template, std::string_view path);

class HttpRequestMetrics {
 public:
  // The routes to label by; requests counted before are labelled "other".
  void set_routes(const std::vector<Route>& routes);

  // The template `path` matches (the one with the fewest `{name}` parts when
  // several do), or "other".
  std::string route_of(std::string_view path) const;

  // One response; seconds: nullopt when the request's start is not known
  // (answered before routing), then only the counter counts it.
  void observe(std::string_view method, std::string_view path, int status, std::optional<double> seconds);

  // Appends both families (HELP and TYPE even without samples).
  void append(std::string& out) const;

 private:
  std::vector<std::string> templates_;  // unique, fewest placeholders first
  mutable std::mutex mu_;
  std::map<std::tuple<std::string, std::string, int>, std::uint64_t> counts_;
  std::map<std::tuple<std::string, std::string, std::string>, MetricsHistogram> durations_;
};

}  // namespace skyfarm::server

#include "server/http/http_request_metrics.h"

#include <algorithm>
#include <array>

#include "server/http/http_metrics.h"

namespace skyfarm::server {
namespace {

constexpr std::array<std::string_view, 7> kMethods = {"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS"};
constexpr std::string_view kOther = "other";

std::string method_label(std::string_view method) {
  return std::find(kMethods.begin(), kMethods.end(), method) != kMethods.end() ? std::string(method)
                                                                               : std::string(kOther);
}

std::size_t placeholders(std::string_view t) { return static_cast<std::size_t>(std::count(t.begin(), t.end(), '{')); }

}  // namespace

// Backtracking over each `{name}`'s length: templates have a handful of
// parts, and a segment is at most a path's length, so this stays tiny.
bool path_matches_template(std::string_view t, std::string_view path) {
  if (t.empty()) return path.empty();
  if (t.front() != '{') {
    const std::size_t open = std::min(t.find('{'), t.size());
    const std::string_view literal = t.substr(0, open);
    return path.starts_with(literal) && path_matches_template(t.substr(open), path.substr(literal.size()));
  }
  const std::size_t close = t.find('}');
  if (close == std::string_view::npos) return false;
  const std::string_view rest = t.substr(close + 1);
  for (std::size_t n = 1; n <= path.size() && path[n - 1] != '/'; ++n)
    if (path_matches_template(rest, path.substr(n))) return true;
  return false;
}

void HttpRequestMetrics::set_routes(const std::vector<Route>& routes) {
  std::vector<std::string> templates;
  for (const Route& r : routes)
    if (std::find(templates.begin(), templates.end(), r.path) == templates.end()) templates.push_back(r.path);
  std::stable_sort(templates.begin(), templates.end(),
                   [](const std::string& a, const std::string& b) { return placeholders(a) < placeholders(b); });
  templates_ = std::move(templates);
}

std::string HttpRequestMetrics::route_of(std::string_view path) const {
  for (const std::string& t : templates_)
    if (path_matches_template(t, path)) return t;
  return std::string(kOther);
}

void HttpRequestMetrics::observe(std::string_view method, std::string_view path, int status,
                                 std::optional<double> seconds) {
  if (status < 100 || status > 599) return;
  std::string route = route_of(path);
  std::string m = method_label(method);
  const std::string code_class = std::to_string(status / 100) + "xx";
  const std::lock_guard lock(mu_);
  ++counts_[{route, m, status}];
  if (!seconds) return;
  auto key = std::make_tuple(std::move(route), std::move(m), code_class);
  auto it = durations_.find(key);
  if (it == durations_.end()) it = durations_.try_emplace(std::move(key), kHttpDurationBucketsS).first;
  it->second.observe(*seconds);
}

void HttpRequestMetrics::append(std::string& out) const {
  const std::lock_guard lock(mu_);
  append_metric_header(out, "skyfarm_http_requests_total", "counter",
                       "HTTP responses sent, by route template, method and status code.");
  for (const auto& [key, n] : counts_) {
    const auto& [route, method, code] = key;
    append_metric_sample(out, "skyfarm_http_requests_total",
                         "code=\"" + std::to_string(code) + "\",method=\"" + method + "\",route=\"" +
                             escaped_label_value(route) + "\"",
                         std::to_string(n));
  }
  std::vector<std::pair<std::string, MetricsHistogram::Snapshot>> series;
  for (const auto& [key, histogram] : durations_) {
    const auto& [route, method, code_class] = key;
    series.emplace_back("code_class=\"" + code_class + "\",method=\"" + method + "\",route=\"" +
                            escaped_label_value(route) + "\"",
                        histogram.snapshot());
  }
  append_histogram(out, "skyfarm_http_request_duration_seconds",
                   "HTTP request duration, routing to response written, by route template.", series);
}

}  // namespace skyfarm::server

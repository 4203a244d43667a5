// GET /metrics: the Prometheus text exposition format (version 0.0.4) of the
// backend's numbers plus what the HTTP layer counts itself (responses by
// route, method and status code, their durations, open event streams) and
// skyfarm_build_info.  Every name is prefixed skyfarm_.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/metrics_histogram.h"
#include "server/http/http_backend.h"

namespace skyfarm::server {

class HttpRequestMetrics;

inline constexpr const char* kPrometheusContentType = "text/plain; version=0.0.4; charset=utf-8";

// Responses by status code (100-599), counted lock-free.
class ResponseCounter {
 public:
  void count(int status);
  // (code, count) for every code seen, in code order.
  std::vector<std::pair<int, std::uint64_t>> snapshot() const;

 private:
  std::array<std::atomic<std::uint64_t>, 600> counts_{};
};

// The exposition text.  `backend` is HttpBackend::metrics(): known keys get
// their documented names (queue_units -> skyfarm_queue_units,
// unit_failures -> skyfarm_unit_failures_total, jobs_<state> ->
// skyfarm_jobs{state="<state>"}, ...); other numeric keys are exported as
// gauges skyfarm_<key>; non-numeric values are skipped.
// `requests`: when given, skyfarm_http_requests_total is labelled by route,
// method and code from it (with the request durations) instead of by code
// alone from `responses`.  `histograms`: the backend's (HttpBackend::histograms()).
std::string prometheus_text(const nlohmann::json& backend, const ResponseCounter& responses,
                            int open_event_streams, const HttpRequestMetrics* requests = nullptr,
                            const std::vector<HistogramSeries>& histograms = {});

// skyfarm_build_info{version,git_commit,compiler,build_type} 1 (build_info.h).
void append_build_info(std::string& out);

// The exposition's pieces, for the parts that append their own families.
void append_metric_header(std::string& out, std::string_view name, std::string_view type, std::string_view help);
void append_metric_sample(std::string& out, std::string_view name, std::string_view labels, const std::string& value);
// A label value with backslash, double quote and newline escaped (the format's rule).
std::string escaped_label_value(std::string_view value);
// One histogram family: HELP, TYPE, then per series (labels without braces,
// "" for none) its cumulative _bucket{...,le="..."} lines up to le="+Inf",
// _sum and _count.  Only the header without series.
void append_histogram(std::string& out, std::string_view name, std::string_view help,
                      const std::vector<std::pair<std::string, MetricsHistogram::Snapshot>>& series);

// The sky look-up caches (server/sky/sky_service.h), appended to `out`, labelled
// cache="table" (built LUT skies) and cache="envmap" (encoded maps):
//   skyfarm_sky_cache_hits_total, _misses_total, _waits_total (waited for a
//   build in progress), _builds_total, _build_failures_total, _evictions_total
//   (counters), skyfarm_sky_cache_bytes, _entries, _capacity_bytes (gauges),
//   skyfarm_sky_cache_build_seconds_total{cache="table"} and
//   skyfarm_sky_cache_sun_only_builds_total{cache="table"} (tables made for a
//   new sun from cached atmosphere tables; counters).
struct SkyCacheStats;
void append_sky_cache_metrics(std::string& out, const SkyCacheStats& stats);

// The farm's probes (server/probes/probe_service.h): skyfarm_probes_total{outcome=
// "done"|"failed"|"timeout"|"no_workers"|"refused"}, skyfarm_probe_units_
// dispatched_total, _units_done_total, _unit_failures_total,
// _unit_requeues_total, _paths_total (counters), skyfarm_probes_active,
// skyfarm_probe_queue_units, _units_in_flight, _workers (gauges).
struct ProbeStats;
void append_probe_metrics(std::string& out, const ProbeStats& stats);

}  // namespace skyfarm::server

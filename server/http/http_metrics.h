// GET /metrics: the Prometheus text exposition format (version 0.0.4) of the
// backend's numbers plus what the HTTP layer counts itself (responses by
// status code, open event streams).  Every name is prefixed skyfarm_.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace skyfarm::server {

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
std::string prometheus_text(const nlohmann::json& backend, const ResponseCounter& responses,
                            int open_event_streams);

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

#include "server/http/http_metrics.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <string_view>

#include "common/core/huge_page_allocator.h"
#include "server/http/build_info.h"
#include "server/http/http_request_metrics.h"
#include "server/probes/probe_service.h"
#include "server/sky/sky_service.h"

namespace skyfarm::server {
namespace {

struct KnownMetric {
  std::string_view key;   // in HttpBackend::metrics()
  std::string_view name;  // exported
  std::string_view type;
  std::string_view help;
};

constexpr KnownMetric kKnown[] = {
    {"queue_units", "skyfarm_queue_units", "gauge", "Work units waiting to be dispatched."},
    {"units_in_flight", "skyfarm_units_in_flight", "gauge", "Work units dispatched to workers and not returned yet."},
    {"workers", "skyfarm_workers", "gauge", "Connected workers."},
    {"samples_per_second", "skyfarm_samples_per_second", "gauge", "Samples merged per second, recent average."},
    {"unit_failures", "skyfarm_unit_failures_total", "counter", "Work units reported failed by workers."},
    {"requeues", "skyfarm_unit_requeues_total", "counter", "Work units requeued (lost worker, timeout, failure)."},
    {"auth_failures", "skyfarm_worker_auth_failures_total", "counter",
     "Worker CURVE handshakes denied or failed (unknown key, wrong mechanism, rate-limited address)."},
    {"results_refused", "skyfarm_results_refused_total", "counter",
     "Results refused: for an attempt not sent to that worker, or not exactly the unit's tile, batches and sample counts."},
    {"assets_served", "skyfarm_assets_served_total", "counter", "Mesh assets sent to workers (ASSET_GET answered)."},
    {"assets_refused", "skyfarm_assets_refused_total", "counter",
     "Mesh assets workers asked for that the server does not have."},
    {"disk_used_bytes", "skyfarm_disk_used_bytes", "gauge", "Bytes the data directory holds (jobs' files, database)."},
    {"disk_budget_bytes", "skyfarm_disk_budget_bytes", "gauge", "The data directory's disk budget in bytes (0: none)."},
    {"samples_total", "skyfarm_samples_total", "counter",
     "Samples (paths) merged into renders since the server started; rate() of it is samples per second."},
    {"units_completed", "skyfarm_units_completed_total", "counter", "Work units merged into renders."},
};
constexpr std::string_view kJobsPrefix = "jobs_";

std::string format_value(const nlohmann::json& v) {
  if (v.is_number_unsigned()) return std::to_string(v.get<std::uint64_t>());
  if (v.is_number_integer()) return std::to_string(v.get<std::int64_t>());
  const double x = v.get<double>();
  if (std::isnan(x)) return "NaN";
  if (std::isinf(x)) return x > 0 ? "+Inf" : "-Inf";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

void header(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
  append_metric_header(out, name, type, help);
}

void sample(std::string& out, std::string_view name, std::string_view labels, const std::string& value) {
  append_metric_sample(out, name, labels, value);
}

// A histogram bound as `le` shows it: the shortest text that reads back as
// the same double ("0.005", "1", "2.5").
std::string le_text(double bound) { return format_value(nlohmann::json(bound)); }

// A metric or label-value name made of [a-zA-Z0-9_] only.
std::string sanitized(std::string_view key) {
  std::string s(key);
  for (char& c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) c = '_';
  return s;
}

void append_known(std::string& out, const nlohmann::json& backend) {
  for (const auto& m : kKnown) {
    const auto it = backend.find(std::string(m.key));
    if (it == backend.end() || !it->is_number()) continue;
    header(out, m.name, m.type, m.help);
    sample(out, m.name, "", format_value(*it));
  }
}

void append_jobs(std::string& out, const nlohmann::json& backend) {
  bool any = false;
  for (auto it = backend.begin(); it != backend.end(); ++it) {
    if (!it.key().starts_with(kJobsPrefix) || !it->is_number()) continue;
    if (!any) header(out, "skyfarm_jobs", "gauge", "Jobs by state.");
    any = true;
    const std::string state = sanitized(std::string_view(it.key()).substr(kJobsPrefix.size()));
    sample(out, "skyfarm_jobs", "state=\"" + state + "\"", format_value(*it));
  }
}

void append_others(std::string& out, const nlohmann::json& backend) {
  std::set<std::string> taken = {"skyfarm_jobs", "skyfarm_http_responses_total", "skyfarm_http_requests_total",
                                 "skyfarm_http_event_streams", "skyfarm_build_info"};
  for (const auto& m : kKnown) {
    taken.insert(std::string(m.name));
    taken.insert("skyfarm_" + std::string(m.key));
  }
  for (auto it = backend.begin(); it != backend.end(); ++it) {
    if (it.key().empty() || it.key().starts_with(kJobsPrefix) || !it->is_number()) continue;
    const std::string name = "skyfarm_" + sanitized(it.key());
    if (!taken.insert(name).second) continue;
    header(out, name, "gauge", "Job service figure \"" + sanitized(it.key()) + "\".");
    sample(out, name, "", format_value(*it));
  }
}

}  // namespace

void append_metric_header(std::string& out, std::string_view name, std::string_view type, std::string_view help) {
  out.append("# HELP ").append(name).append(" ").append(help).append("\n");
  out.append("# TYPE ").append(name).append(" ").append(type).append("\n");
}

void append_metric_sample(std::string& out, std::string_view name, std::string_view labels, const std::string& value) {
  out.append(name);
  if (!labels.empty()) out.append("{").append(labels).append("}");
  out.append(" ").append(value).append("\n");
}

std::string escaped_label_value(std::string_view value) {
  std::string s;
  for (const char c : value) {
    if (c == '\\' || c == '"') s += '\\';
    if (c == '\n') s += "\\n";
    else s += c;
  }
  return s;
}

void append_histogram(std::string& out, std::string_view name, std::string_view help,
                      const std::vector<std::pair<std::string, MetricsHistogram::Snapshot>>& series) {
  append_metric_header(out, name, "histogram", help);
  const std::string bucket = std::string(name) + "_bucket", sum = std::string(name) + "_sum",
                    count = std::string(name) + "_count";
  for (const auto& [labels, s] : series) {
    const std::string prefix = labels.empty() ? std::string() : labels + ",";
    for (std::size_t i = 0; i < s.cumulative.size(); ++i) {
      const std::string le = i < s.upper_bounds.size() ? le_text(s.upper_bounds[i]) : std::string("+Inf");
      append_metric_sample(out, bucket, prefix + "le=\"" + le + "\"", std::to_string(s.cumulative[i]));
    }
    append_metric_sample(out, sum, labels, format_value(nlohmann::json(s.sum)));
    append_metric_sample(out, count, labels, std::to_string(s.count));
  }
}

void append_build_info(std::string& out) {
  const BuildInfo& b = build_info();
  append_metric_header(out, "skyfarm_build_info", "gauge",
                       "Always 1; which build serves: its version, commit, compiler and build type.");
  append_metric_sample(out, "skyfarm_build_info",
                       "version=\"" + escaped_label_value(b.version) + "\",git_commit=\"" +
                           escaped_label_value(b.git_commit) + "\",compiler=\"" + escaped_label_value(b.compiler) +
                           "\",build_type=\"" + escaped_label_value(b.build_type) + "\"",
                       "1");
}

void ResponseCounter::count(int status) {
  if (status >= 100 && status < static_cast<int>(counts_.size()))
    counts_[static_cast<std::size_t>(status)].fetch_add(1, std::memory_order_relaxed);
}

std::vector<std::pair<int, std::uint64_t>> ResponseCounter::snapshot() const {
  std::vector<std::pair<int, std::uint64_t>> out;
  for (std::size_t code = 100; code < counts_.size(); ++code)
    if (const auto n = counts_[code].load(std::memory_order_relaxed); n > 0)
      out.emplace_back(static_cast<int>(code), n);
  return out;
}

std::string prometheus_text(const nlohmann::json& backend, const ResponseCounter& responses,
                            int open_event_streams, const HttpRequestMetrics* requests,
                            const std::vector<HistogramSeries>& histograms) {
  std::string out;
  append_build_info(out);
  if (backend.is_object()) {
    append_known(out, backend);
    append_jobs(out, backend);
    append_others(out, backend);
  }
  // The backend's histograms, a family per name in the order first named.
  std::vector<std::string> names;
  for (const HistogramSeries& h : histograms)
    if (std::find(names.begin(), names.end(), h.name) == names.end()) names.push_back(h.name);
  for (const std::string& name : names) {
    std::vector<std::pair<std::string, MetricsHistogram::Snapshot>> series;
    std::string help;
    for (const HistogramSeries& h : histograms)
      if (h.name == name) {
        series.emplace_back(h.labels, h.snapshot);
        help = h.help;
      }
    append_histogram(out, name, help, series);
  }
  if (requests) {
    requests->append(out);
  } else {
    header(out, "skyfarm_http_requests_total", "counter", "HTTP responses sent, by status code.");
    for (const auto& [code, n] : responses.snapshot())
      sample(out, "skyfarm_http_requests_total", "code=\"" + std::to_string(code) + "\"", std::to_string(n));
  }
  header(out, "skyfarm_http_event_streams", "gauge", "Open Server-Sent Events streams.");
  sample(out, "skyfarm_http_event_streams", "", std::to_string(open_event_streams));
  return out;
}

void append_sky_cache_metrics(std::string& out, const SkyCacheStats& s) {
  struct Pair {
    std::string_view name, type, help;
    double table, envmap;
  };
  const Pair pairs[] = {
      {"skyfarm_sky_cache_hits_total", "counter", "Sky look-ups answered from the cache.",
       double(s.table_hits), double(s.envmap_hits)},
      {"skyfarm_sky_cache_misses_total", "counter", "Sky look-ups that started a build.",
       double(s.table_misses), double(s.envmap_misses)},
      {"skyfarm_sky_cache_waits_total", "counter", "Sky look-ups that waited for a build already in progress.",
       double(s.table_waits), double(s.envmap_waits)},
      {"skyfarm_sky_cache_builds_total", "counter", "Sky cache entries built.",
       double(s.table_builds), double(s.envmap_builds)},
      {"skyfarm_sky_cache_build_failures_total", "counter", "Sky cache builds that failed (not cached).",
       double(s.table_build_failures), double(s.envmap_build_failures)},
      {"skyfarm_sky_cache_evictions_total", "counter", "Sky cache entries evicted to stay within the byte bound.",
       double(s.table_evictions), double(s.envmap_evictions)},
      {"skyfarm_sky_cache_bytes", "gauge", "Bytes held by the sky cache.",
       double(s.table_bytes), double(s.envmap_bytes)},
      {"skyfarm_sky_cache_entries", "gauge", "Entries in the sky cache.",
       double(s.table_entries), double(s.envmap_entries)},
      {"skyfarm_sky_cache_capacity_bytes", "gauge", "Byte bound of the sky cache.",
       double(s.table_capacity_bytes), double(s.envmap_capacity_bytes)},
  };
  for (const auto& p : pairs) {
    header(out, p.name, p.type, p.help);
    sample(out, p.name, "cache=\"table\"", format_value(p.table));
    sample(out, p.name, "cache=\"envmap\"", format_value(p.envmap));
  }
  header(out, "skyfarm_sky_cache_build_seconds_total", "counter", "Seconds spent building sky tables.");
  sample(out, "skyfarm_sky_cache_build_seconds_total", "cache=\"table\"", format_value(s.table_build_seconds));
  header(out, "skyfarm_sky_cache_sun_only_builds_total", "counter",
         "Sky tables built for a new sun from cached atmosphere tables (LutSky::with_sun).");
  sample(out, "skyfarm_sky_cache_sun_only_builds_total", "cache=\"table\"",
         std::to_string(s.table_sun_only_builds));
  header(out, "skyfarm_table_memory_recycled_bytes", "gauge",
         "Freed table memory kept for the next build of the same size (huge_page_allocator.h; at most 64 MiB).");
  sample(out, "skyfarm_table_memory_recycled_bytes", "", std::to_string(recycled_bytes()));
}

void append_probe_metrics(std::string& out, const ProbeStats& s) {
  header(out, "skyfarm_probes_total", "counter", "Path-traced probes through the farm, by outcome.");
  const std::pair<const char*, std::uint64_t> outcomes[] = {
      {"done", s.done},           {"failed", s.failed},         {"timeout", s.timed_out},
      {"no_workers", s.no_workers}, {"refused", s.refused_capacity}};
  for (const auto& [outcome, n] : outcomes)
    sample(out, "skyfarm_probes_total", std::string("outcome=\"") + outcome + "\"", std::to_string(n));
  struct One {
    std::string_view name, type, help;
    std::uint64_t value;
  };
  const One ones[] = {
      {"skyfarm_probes_active", "gauge", "Probes waiting for their answer.", s.active},
      {"skyfarm_probe_queue_units", "gauge", "Probe units waiting to be dispatched.", s.queue_units},
      {"skyfarm_probe_units_in_flight", "gauge", "Probe units dispatched and not returned yet.", s.units_in_flight},
      {"skyfarm_probe_workers", "gauge", "Connected workers that run probe units.", s.workers},
      {"skyfarm_probe_units_dispatched_total", "counter", "Probe units sent to workers.", s.units_dispatched},
      {"skyfarm_probe_units_done_total", "counter", "Probe units merged.", s.units_done},
      {"skyfarm_probe_unit_failures_total", "counter", "Probe units reported failed (or unreadable).",
       s.unit_failures},
      {"skyfarm_probe_unit_requeues_total", "counter", "Probe units dispatched again (lost worker, timeout).",
       s.requeues},
      {"skyfarm_probe_paths_total", "counter", "Paths traced for merged probe units.", s.paths},
  };
  for (const auto& o : ones) {
    header(out, o.name, o.type, o.help);
    sample(out, o.name, "", std::to_string(o.value));
  }
}

}  // namespace skyfarm::server

// What the HTTP layer needs of the farm's jobs, and the answers it gets:
// implemented by JobService (jobs/job_service.h); tests fake it.  The routes that use it are
// in http_api.h.
#pragma once
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "common/core/metrics_histogram.h"
#include "server/jobs/job_errors.h"

namespace skyfarm::server {

struct SubmitResult {
  std::string id;
  bool created = false;     // false: an existing job (idempotent replay or result cache)
  bool from_cache = false;  // an identical request already rendered
};

enum class ImageFormat { kExr, kPng };

struct ImageFile {
  std::filesystem::path path;  // a complete file, safe to read while the job runs on
  std::string etag;            // strong ETag (quoted), changes whenever the image does
  bool final = false;          // the job is done: the image will not change
};

// One progress event for Server-Sent Events.
struct JobEvent {
  std::uint64_t sequence = 0;  // per job, increasing from 1
  std::string type;            // "queued", "progress", "done", "failed", "cancelled"
  nlohmann::json data;         // the status document at that moment
};

// DELETE /v1/renders/{id}?purge=true.
struct PurgeOutcome {
  enum Kind { kPurged, kUnknown, kConflict } kind = kUnknown;
  std::string detail;  // kConflict: why not (a timelapse's frame, an image being written)
};

// One series of a /metrics histogram: its family's name and help, its labels
// as exposed without braces (`method="path"`, "" for none), its counts.
struct HistogramSeries {
  std::string name;
  std::string help;
  std::string labels;
  MetricsHistogram::Snapshot snapshot;
};

class HttpBackend {
 public:
  virtual ~HttpBackend() = default;
  // May throw IdempotencyConflict, CapacityExceeded, StorageError, InsufficientStorage.
  virtual SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& idempotency_key) = 0;
  // The status document (docs/request-schema.md; its field names are a
  // contract), or nullopt for an unknown id.
  virtual std::optional<nlohmann::json> status(const std::string& id) const = 0;
  // Newest first; each entry a status document.
  virtual nlohmann::json list(std::size_t offset, std::size_t limit) const = 0;
  virtual std::size_t job_count() const = 0;
  // false for an unknown id; cancelling a finished job is a no-op returning true.
  virtual bool cancel(const std::string& id) = 0;
  // Cancels the job if it is active, then removes its files and its record:
  // afterwards the id is unknown.  Backends without files answer kConflict.
  virtual PurgeOutcome purge(const std::string& id) {
    return {PurgeOutcome::kConflict, "render \"" + id + "\" cannot be purged by this server"};
  }
  // nullopt until every unit of the first pass has been merged, for an unknown
  // id, for a cancelled or failed job (its partial results are deleted) and
  // for an expired one (status "expired": true).
  virtual std::optional<ImageFile> image(const std::string& id, ImageFormat format) = 0;
  // Events with sequence > after; waits up to `timeout` for one; empty on timeout.
  virtual std::vector<JobEvent> events_after(const std::string& id, std::uint64_t after,
                                             std::chrono::milliseconds timeout) = 0;
  // GET /v1/workers: [{"id", "cores", "version", "units_done", "units_in_flight", "draining", "last_seen_s"}].
  virtual nlohmann::json workers() const = 0;
  // POST /v1/workers/{id}/drain and .../resume: a drained worker gets no new
  // units (those in flight finish) until resumed.  false: no such worker
  // connected (404); backends without workers have none.
  virtual bool set_worker_draining(const std::string& /*worker_id*/, bool /*draining*/) { return false; }
  // /metrics material: {"queue_units", "units_in_flight", "jobs_queued", "jobs_running", "jobs_done",
  // "jobs_failed", "workers", "samples_per_second", "unit_failures", "requeues", "results_refused", "disk_used_bytes",
  // "disk_budget_bytes" (0: no limit)} (numbers).
  virtual nlohmann::json metrics() const = 0;
  // /metrics histograms (skyfarm_unit_duration_seconds, ...), one entry per
  // series; entries of one name are one family.  None by default.
  virtual std::vector<HistogramSeries> histograms() const { return {}; }
};

}  // namespace skyfarm::server

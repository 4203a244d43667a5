// The farm's core, between the HTTP layer (http_api.h) and the ZeroMQ broker
// (broker.h): jobs, their units of work, attempts, merging and persistence.
// Every method is thread-safe (one internal mutex); neither the HTTP threads
// nor the broker thread ever touch another's sockets.
//
// A job is a validated render request cut by its RenderPlan into units
// (tile, batch, pass).  Units are handed out pass-major (every tile and batch
// of pass 0, then pass 1, ...) so the whole frame gets its first samples
// before any tile gets its second pass.  The highest priority with work wins
// outright; within it the jobs share the workers fairly (the one with the
// fewest units in flight is served next, a timelapse's frames counting as
// one), so a small job is not stuck behind a huge one.  A result is merged
// only if it is exactly what its unit asked for (unit_result_check.h), and
// into its tile only in canonical
// (pass, batch) order; early results wait in memory.  Merged tiles are
// written atomically to the data directory (each at most once a second while
// it merges, and all of them before a job is done), so a restarted server
// resumes from its merged passes (and hands out again what it merged after
// the last write) and the final image is bit-identical to
// `skyfarm-worker render`.
//
// Disk (ServiceLimits::max_disk_bytes, retention_hours; disk_budget.h): a job
// is admitted only if its files at their final size fit in the budget beside
// what the others hold and may still write (InsufficientStorage otherwise,
// nothing made).  A job's tiles are deleted once it is done (after its final
// image is written), failed or cancelled; a finished job's directory is
// removed after the retention (its record stays, "expired"); purge removes a
// job's files and record at once.
#pragma once
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "api/wire.h"

namespace skyfarm::server {

using Clock = std::chrono::steady_clock;

// --- Identifiers ------------------------------------------------------------

struct UnitKey {
  std::string job_id;
  int tile = 0, batch = 0, pass = 0;
  bool operator==(const UnitKey&) const = default;
};

// What the broker sends to a worker for one unit.
struct UnitAssignment {
  UnitKey key;
  std::uint64_t attempt = 0;       // unique per dispatch; results of other attempts are dropped
  std::string request_canonical;   // api::canonical_text of the job's request (workers cache the setup per job)
  api::UnitKind kind = api::UnitKind::kRender;  // kProbe: a radiance probe's unit (server/probes/probe_service.h)
  // An adaptive job's samples per pass after its pilot, per allocation block
  // of the tile, (even, odd) pixels (api::UnitMsg); empty: uniform.
  std::vector<std::pair<int, int>> samples_per_pass{};
};

// --- Errors the HTTP layer maps to status codes ------------------------------

// 422: an Idempotency-Key reused with a different body.
struct IdempotencyConflict : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// 429: too many active jobs or a full queue.
struct CapacityExceeded : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// 500-class: the data directory cannot be written (disk full, permissions).
struct StorageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// 507: the job would not fit in the disk budget (ServiceLimits::max_disk_bytes);
// the message says how much it needs and how much is free.
struct InsufficientStorage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// --- Results for the HTTP layer ------------------------------------------

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
  std::string type;            // "progress", "done", "failed", "cancelled"
  nlohmann::json data;         // the status document at that moment
};

// A job's state in brief, cheaper than its status document (a timelapse
// follows many frames).
struct JobSummary {
  std::string state;
  double fraction = 0.0;                          // progress towards the first limit (render_progress.h; 1 when done)
  std::optional<double> estimated_relative_rms;   // after the first complete pass
  std::string failure;                            // when failed
};

struct ServiceLimits {
  int max_active_jobs = 64;       // queued + running
  int max_queue_units = 4000000;  // units waiting over all jobs (at most 16 passes of each)
  double unit_timeout_s = 120.0;  // a dispatched unit with no result after this is requeued
  int max_unit_failures = 3;      // distinct workers failing a unit fails its job
  // The data directory's disk budget in bytes: a job whose files (disk_budget.h)
  // would not fit beside what the others hold and may still write is refused
  // (InsufficientStorage).  0: no limit; < 0: default_disk_budget at start.
  std::int64_t max_disk_bytes = 0;
  // A job finished (done, failed, cancelled) longer ago than this expires:
  // its directory is removed, its record stays (status "expired": true, its
  // images gone).  0: never.
  double retention_hours = 168.0;
};

// DELETE /v1/renders/{id}?purge=true.
struct PurgeOutcome {
  enum Kind { kPurged, kUnknown, kConflict } kind = kUnknown;
  std::string detail;  // kConflict: why not (a timelapse's frame, an image being written)
};

// What the HTTP layer needs (implemented by JobService; tests may fake it).
class HttpBackend {
 public:
  virtual ~HttpBackend() = default;
  // May throw IdempotencyConflict, CapacityExceeded, StorageError.
  virtual SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& idempotency_key) = 0;
  // The status document of DESIGN §5.3 (field names are a contract), or nullopt for an unknown id.
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
  // GET /v1/workers: [{"id", "cores", "version", "units_done", "units_in_flight", "last_seen_s"}].
  virtual nlohmann::json workers() const = 0;
  // /metrics material: {"queue_units", "units_in_flight", "jobs_queued", "jobs_running", "jobs_done",
  // "jobs_failed", "workers", "samples_per_second", "unit_failures", "requeues", "results_refused", "disk_used_bytes",
  // "disk_budget_bytes" (0: no limit)} (numbers).
  virtual nlohmann::json metrics() const = 0;
};

// What the ZeroMQ broker needs (implemented by JobService; tests may fake it).
class BrokerBackend {
 public:
  virtual ~BrokerBackend() = default;
  // READY: {"id", "cores", "slots", "version", "capabilities": {...}}.
  virtual void worker_joined(const std::string& worker_id, const nlohmann::json& info) = 0;
  // Lost (missed heartbeats) or disconnected: its units are requeued.
  virtual void worker_left(const std::string& worker_id) = 0;
  // The next unit for a worker with a free slot, or nullopt.
  virtual std::optional<UnitAssignment> next_unit(const std::string& worker_id) = 0;
  // A result (FilmTile::serialize bytes); stale attempts and cancelled jobs are dropped.
  virtual void unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                         const std::vector<std::uint8_t>& film_tile_bytes, std::uint64_t paths) = 0;
  virtual void unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                           const std::string& message) = 0;
  // (worker id, attempt) of dispatched units that must stop (job cancelled, unit superseded).
  virtual std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts() = 0;
  // Requeues units dispatched longer ago than the unit timeout.
  virtual void check_timeouts(Clock::time_point now) = 0;
};

class JobService final : public HttpBackend, public BrokerBackend {
 public:
  JobService(std::filesystem::path data_dir, ServiceLimits limits = {});
  ~JobService() override;
  JobService(const JobService&) = delete;
  JobService& operator=(const JobService&) = delete;

  SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& idempotency_key) override;
  std::optional<nlohmann::json> status(const std::string& id) const override;
  nlohmann::json list(std::size_t offset, std::size_t limit) const override;
  std::size_t job_count() const override;
  bool cancel(const std::string& id) override;
  PurgeOutcome purge(const std::string& id) override;
  std::optional<ImageFile> image(const std::string& id, ImageFormat format) override;
  std::vector<JobEvent> events_after(const std::string& id, std::uint64_t after,
                                     std::chrono::milliseconds timeout) override;
  nlohmann::json workers() const override;
  nlohmann::json metrics() const override;

  void worker_joined(const std::string& worker_id, const nlohmann::json& info) override;
  void worker_left(const std::string& worker_id) override;
  std::optional<UnitAssignment> next_unit(const std::string& worker_id) override;
  void unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                 const std::vector<std::uint8_t>& film_tile_bytes, std::uint64_t paths) override;
  void unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                   const std::string& message) override;
  std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts() override;
  void check_timeouts(Clock::time_point now) override;

  // Expires the jobs finished more than ServiceLimits::retention_hours
  // before now_unix (check_timeouts does so once a minute); returns how many.
  std::size_t expire_finished(double now_unix);

  // --- For timelapses (server/timelapse/timelapse_service.h) ---------------------------
  // Jobs of one group (a timelapse's frames) share out their passes: they
  // count as one tenant in the fair share (next_unit), and when that tenant
  // is served the unit handed out is the one of the lowest next pass among
  // the group's jobs of the same priority (ties: submission order), so every
  // frame gets pass p before any gets pass p + 1 and the frames fill in
  // together.  Groups are not
  // persisted: their owner sets them again after a restart.  false: unknown id.
  bool set_group(const std::string& id, const std::string& group);
  std::optional<JobSummary> summary(const std::string& id) const;
  // Called with (job id, new state) on every state change, under the
  // service's lock: it must not call into the service (wake a thread instead).
  // An empty function removes the observer.
  void set_state_observer(std::function<void(const std::string&, const std::string&)> observer);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skyfarm::server

// The job service's shared state: every job, the attempts in flight, the
// workers, the idempotency keys and the disk accounting, under one mutex,
// with the operations that more than one part of the service needs (a job
// added or restored, a state change and its event, a job failed, cancelled,
// purged or expired, an attempt requeued).  The parts, each of one
// responsibility, work on it:
//   admission.h      submit: idempotency, the result cache, capacity, disk
//   scheduler.h      workers, fair dispatch, timeouts and requeues
//   result_intake.h  results checked and merged, passes recorded, jobs finished
//   job_images.h     the merged sums as EXR and PNG
//   job_status.cpp   the status document and the metrics
// and job_service.h is their front: it takes the lock, then calls them.
//
// Every method here is called with `mu` held.
#pragma once
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/metrics_histogram.h"
#include "server/http/http_backend.h"
#include "server/jobs/job.h"
#include "server/jobs/job_state.h"
#include "server/jobs/job_store.h"
#include "server/jobs/service_limits.h"

namespace skyfarm::server {

// One dispatched unit awaiting its result, by attempt id.
struct InFlight {
  std::string job_id;
  WorkUnit unit;
  std::string worker;
  Clock::time_point since;
};

struct WorkerInfo {
  nlohmann::json info;
  int units_done = 0;
  int in_flight = 0;
  Clock::time_point last_seen;
};

// A tile is written at most this often while it merges (tile_merger.h): tiny
// units merge thousands of times a second.  A crash loses at most this much
// merging (those units are handed out again), never a merged image: a job's
// tiles are all written before it is done.
inline constexpr std::chrono::milliseconds kTilePersistInterval{1000};

using StateObserver = std::function<void(const std::string&, JobState)>;

struct JobBook {
  std::filesystem::path data_dir;
  ServiceLimits limits;
  std::unique_ptr<JobStore> store;
  mutable std::mutex mu;
  std::condition_variable changed;  // a job's events grew, or it was purged
  std::map<std::string, std::unique_ptr<Job>> jobs;
  std::vector<std::string> order;  // submission order
  // The jobs that may still get units, in submission order (the scheduler
  // prunes the finished), so that dispatch scans neither finished jobs nor units.
  std::vector<Job*> runnable;
  std::map<std::string, std::string> idempotency;  // key → job id
  std::map<std::uint64_t, InFlight> in_flight;      // by attempt
  std::uint64_t next_attempt = 1;
  std::vector<std::pair<std::string, std::uint64_t>> cancelled;  // (worker, attempt) to stop
  std::map<std::string, WorkerInfo> workers;
  // Workers an operator drained (POST /v1/workers/{id}/drain): they get no
  // new units until resumed, even after they reconnect under the same id.
  std::set<std::string> drained_workers;
  std::int64_t next_sequence = 1;
  std::uint64_t unit_failures = 0, requeues = 0, results_refused = 0;
  // /metrics: samples (paths) and units merged since start (counters), and
  // durations: a unit from dispatch to merged, by method; a job from
  // submission to its end, by final state (done, failed, cancelled).
  std::uint64_t samples_total = 0, units_completed = 0;
  MetricsHistogram unit_seconds_path{kUnitDurationBucketsS}, unit_seconds_lut{kUnitDurationBucketsS};
  MetricsHistogram job_seconds_done{kJobDurationBucketsS}, job_seconds_failed{kJobDurationBucketsS},
      job_seconds_cancelled{kJobDurationBucketsS};
  std::deque<std::pair<Clock::time_point, std::uint64_t>> recent_paths;  // for samples/s
  StateObserver state_observer;
  // Disk: the budget (0: none), the data directory's bytes outside the jobs'
  // directories (measured at start: the database, timelapses), purged jobs
  // kept for threads that still hold them (image()), and the last expiry.
  std::int64_t disk_budget = 0;
  std::int64_t base_bytes = 0;
  std::vector<std::unique_ptr<Job>> purged;
  Clock::time_point last_expiry{};

  std::int64_t disk_used() const;
  // What the budget counts: a running job its estimate (it may write that much).
  std::int64_t disk_reserved() const;
  // The bytes of the job's files other than its tiles, measured again.
  void measure(Job& job);

  // A job from its record (new, or restored at start), with its plan, merger
  // and files read back.
  Job& add_job(JobRecord record, api::RenderRequest request);
  void set_state(Job& job, JobState state, const std::string& failure = "");
  // Appends an event with the job's status document ("progress" events are
  // thinned: see the definition).
  void emit(Job& job, const std::string& type);
  // The "progress" events emit held back, once their interval has passed.
  void flush_held_progress(Clock::time_point now);
  // Writes the merged tiles whose persistence interval has passed.
  void flush_due_tiles(Clock::time_point now);
  // The status document (job_status.cpp).
  nlohmann::json status_of(const Job& job) const;
  // GET /metrics material (job_status.cpp).
  nlohmann::json metrics() const;
  std::vector<HistogramSeries> histograms() const;

  // The job's dispatched units are to stop and its requeued ones are dropped.
  void drop_attempts_of(Job& job);
  // The attempt's unit goes back to its job's queue (unless merged already);
  // tell_worker: the worker is told to stop it.
  void requeue(std::uint64_t attempt, bool tell_worker);
  void fail_job(Job& job, const std::string& message);
  // An active job stops: "cancelled", its tiles deleted.
  void cancel(Job& job);
  // DELETE ...?purge=true: the job cancelled if active, then its files and
  // record removed.
  PurgeOutcome purge(const std::string& id);
  // A finished, failed or cancelled job's tiles are deleted: only a resume
  // reads them, and its status keeps their counts (report.json).  Nothing
  // else reads a finished job's tiles: the final image, its error history
  // and the timelapses' frames (their final EXRs) are files of their own.
  void release_tiles(Job& job);
  // Expires the jobs finished more than the retention before now_unix.
  std::size_t expire(double now_unix);
};

}  // namespace skyfarm::server

// The job service's limits, from the server's flags (server_options.h).
#pragma once
#include <cstdint>

namespace skyfarm::server {

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

}  // namespace skyfarm::server

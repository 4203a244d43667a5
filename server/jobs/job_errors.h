// The errors the job service throws, each one an HTTP status to the HTTP
// layer (http_problem.h maps them), so that nothing needs the service itself
// to catch them.
#pragma once
#include <stdexcept>

namespace skyfarm::server {

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

}  // namespace skyfarm::server

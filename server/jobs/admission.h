// Admission of a render request (POST /v1/renders): an Idempotency-Key
// replayed answers its job (or 422 for a different body); an identical
// request done or on its way answers that job (the result cache: the
// canonical request without its priority, hashed); otherwise the job is
// admitted only within the limits — active jobs, units waiting in the queue,
// and the disk budget (its files at their final size must fit beside what the
// others hold and may still write) — and nothing is made when it is refused.
#pragma once
#include <optional>
#include <string>

#include "api/render_request.h"
#include "server/http/http_backend.h"
#include "server/jobs/job_book.h"

namespace skyfarm::server {

class Admission {
 public:
  explicit Admission(JobBook& book) : book_(book) {}
  // Under the book's lock.  Throws IdempotencyConflict, CapacityExceeded,
  // InsufficientStorage, StorageError.
  SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& key);

 private:
  JobBook& book_;
};

}  // namespace skyfarm::server

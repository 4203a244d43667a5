#include "server/jobs/admission.h"

#include <algorithm>
#include <sstream>

#include "api/render_spec.h"
#include "common/sampling/sampler.h"
#include "common/sun/sun.h"
#include "server/jobs/disk_budget.h"
#include "server/jobs/job_ids.h"

namespace skyfarm::server {
namespace {

// The result-cache key: the canonical request without its priority (which
// changes when a job runs, not what it renders), hashed.
std::string request_hash(const api::RenderRequest& request) {
  nlohmann::json j = api::to_canonical_json(request);
  j.erase("priority");
  const std::string text = j.dump();
  std::uint64_t h1 = 0x9e3779b97f4a7c15ULL, h2 = 0xc2b2ae3d27d4eb4fULL;
  for (unsigned char c : text) {
    h1 = fmix64(h1 ^ c);
    h2 = fmix64(h2 + c * 0x100000001b3ULL);
  }
  std::ostringstream o;
  o << std::hex << h1 << h2;
  return o.str();
}

}  // namespace

SubmitResult Admission::submit(const api::RenderRequest& request, const std::optional<std::string>& key) {
  const std::string canonical = api::canonical_text(request);
  const std::string hash = request_hash(request);
  if (key) {
    const auto it = book_.idempotency.find(*key);
    if (it != book_.idempotency.end()) {
      const Job& job = *book_.jobs.at(it->second);
      if (job.record.request != canonical)
        throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used for a different request (job " +
                                  job.record.id + ")");
      return {job.record.id, false, false};
    }
  }
  // Result cache: an identical request that is done, or still on its way
  // (its name aside: the job answered keeps the name it was given).
  for (const auto& id : book_.order) {
    const Job& job = *book_.jobs.at(id);
    if (job.record.request_hash == hash && ((job.record.state == JobState::kDone && !job.expired) || job.active() || job.finishing)) {
      if (key) book_.idempotency[*key] = job.record.id;
      return {job.record.id, false, job.record.state == JobState::kDone};
    }
  }
  int active = 0;
  std::int64_t queued_units = 0;
  for (const auto& [id, job] : book_.jobs) {
    if (!job->active()) continue;
    ++active;
    queued_units += waiting_units(job->plan, job->merger->merged_units());
  }
  if (active >= book_.limits.max_active_jobs)
    throw CapacityExceeded("too many active jobs (" + std::to_string(active) + "); try again later");
  const RenderPlan plan = api::render_plan_for(request, Sun::from_spec(request.sun, request.location, request.time));
  const std::int64_t units = waiting_units(plan, 0);
  if (units > book_.limits.max_queue_units)
    throw CapacityExceeded("this render alone is " + std::to_string(units) + " units of work (" +
                           std::to_string(plan.tile_count()) + " tiles x " + std::to_string(plan.batches) +
                           " batches x " + std::to_string(std::min<std::int64_t>(plan.passes, kQueueHorizonPasses)) +
                           " passes), more than the queue's " + std::to_string(book_.limits.max_queue_units) +
                           "; fewer pixels, batches or samples_per_pixel");
  if (queued_units + units > book_.limits.max_queue_units)
    throw CapacityExceeded("the queue is full (" + std::to_string(queued_units) + " units waiting); try again later");
  if (book_.disk_budget > 0) {
    const std::int64_t needs = estimated_job_bytes(request, plan);
    const std::int64_t committed = book_.disk_reserved();
    if (committed + needs > book_.disk_budget) {
      constexpr std::int64_t kMiB = 1 << 20;
      const std::int64_t free_mib = std::max<std::int64_t>(0, book_.disk_budget - committed) / kMiB;
      throw InsufficientStorage(
          "this render needs about " + std::to_string((needs + kMiB - 1) / kMiB) + " MiB of disk (" +
          std::to_string(plan.tile_count()) + " tiles x " + std::to_string(plan.batches) +
          (plan.batches == 1 ? " batch" : " batches") + ", and its images); the disk budget (--max-disk-mb " + std::to_string(book_.disk_budget / kMiB) +
          ") has " + std::to_string(free_mib) + " MiB free. Render fewer pixels or batches, wait for running "
          "renders to finish, or free space by deleting a finished render (DELETE /v1/renders/{id}?purge=true)");
    }
  }

  JobRecord r;
  r.id = random_id();
  r.request = canonical;
  r.request_hash = hash;
  r.priority = request.priority;
  r.state = JobState::kQueued;
  r.created_unix = unix_now();
  r.idempotency_key = key.value_or("");
  r.sequence = book_.next_sequence++;
  r.name = request.name.value_or("");
  book_.store->insert(r);
  Job& job = book_.add_job(std::move(r), request);
  book_.emit(job, "queued");
  return {job.record.id, true, false};
}

}  // namespace skyfarm::server

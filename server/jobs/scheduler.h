// Scheduling: the workers the broker reports, which unit each gets next, and
// the units that come back to the queue (a worker lost, a unit timed out).
//
// Units are handed out pass-major (every tile and batch of pass 0, then pass
// 1, ...) so the whole frame gets its first samples before any tile gets its
// second pass; requeued units go first.  The highest priority with work wins
// outright; within it the jobs share the workers fairly: the tenant (a job,
// or a group's jobs: a timelapse's frames) with the fewest units in flight is
// served next, so a small job is not stuck behind a huge one.  An adaptive
// job hands out no unit beyond its pilot pass until its allocation is made
// (result_intake.h).  A worker an operator drained gets no unit at all.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/jobs/job_book.h"
#include "server/jobs/unit_assignment.h"

namespace skyfarm::server {

// Every method is called under the book's lock.
class Scheduler {
 public:
  explicit Scheduler(JobBook& book) : book_(book) {}

  void worker_joined(const std::string& worker_id, const nlohmann::json& info);
  // Its units in flight are requeued.
  void worker_left(const std::string& worker_id);
  std::optional<UnitAssignment> next_unit(const std::string& worker_id);
  std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts();
  // Requeues units dispatched longer ago than the unit timeout.
  void requeue_late(Clock::time_point now);
  // GET /v1/workers.
  nlohmann::json workers() const;
  // Drains a worker (no new units; those in flight finish) or resumes it;
  // false for a worker that is not connected.
  bool set_draining(const std::string& worker_id, bool draining);

 private:
  // The job whose tenant is served next, or nullptr when no job has work.
  Job* fair_choice();
  // Among `chosen`'s group at its priority, the job whose next unit has the
  // lowest pass; the earliest submitted on a tie.
  Job& lowest_pass_in_group(Job& chosen);

  JobBook& book_;
};

}  // namespace skyfarm::server

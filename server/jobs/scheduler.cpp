#include "server/jobs/scheduler.h"

#include <algorithm>

namespace skyfarm::server {
namespace {

// The pass of the unit a job would hand out next (requeued units first).
int next_pass(const Job& job) {
  if (!job.requeued.empty()) return job.requeued.front().pass;
  return unit_at(job.plan, job.cursor).pass;
}

}  // namespace

void Scheduler::worker_joined(const std::string& worker_id, const nlohmann::json& info) {
  WorkerInfo& w = book_.workers[worker_id];
  w.info = info;
  w.last_seen = Clock::now();
}

void Scheduler::worker_left(const std::string& worker_id) {
  std::vector<std::uint64_t> attempts;
  for (const auto& [a, f] : book_.in_flight)
    if (f.worker == worker_id) attempts.push_back(a);
  for (auto a : attempts) book_.requeue(a, false);
  book_.workers.erase(worker_id);
}

std::optional<UnitAssignment> Scheduler::next_unit(const std::string& worker_id) {
  auto& workers = book_.workers;
  if (auto w = workers.find(worker_id); w != workers.end()) w->second.last_seen = Clock::now();
  if (book_.drained_workers.contains(worker_id)) return std::nullopt;
  Job* picked = nullptr;
  std::optional<WorkUnit> unit;
  // A job whose units left turn out to be received already has no work after
  // this look (its queue drained, its cursor at the end or at the allocation
  // gate), so the next choice is another: the loop ends.
  while (!unit) {
    Job* chosen = fair_choice();
    if (!chosen) return std::nullopt;
    picked = chosen->group.empty() ? chosen : &lowest_pass_in_group(*chosen);
    Job& job = *picked;
    while (!job.requeued.empty() && !unit) {
      const WorkUnit u = job.requeued.front();
      job.requeued.pop_front();
      if (!job.merger->received(u)) unit = u;
    }
    while (!unit && job.cursor < static_cast<std::size_t>(job.plan.unit_count())) {
      if (job.waits_for_allocation() && unit_at(job.plan, job.cursor).pass > 0) break;
      const WorkUnit u = unit_at(job.plan, job.cursor++);
      if (!job.merger->received(u)) unit = u;
    }
  }
  Job& job = *picked;
  if (!job.started) {
    job.started = true;
    job.start_time = Clock::now();
  }
  if (job.record.state == JobState::kQueued) {
    book_.set_state(job, JobState::kRunning);
    book_.emit(job, "progress");
  }
  const std::uint64_t attempt = book_.next_attempt++;
  book_.in_flight[attempt] = InFlight{job.record.id, *unit, worker_id, Clock::now()};
  ++job.in_flight;
  ++job.dispatched;
  if (auto w = workers.find(worker_id); w != workers.end()) ++w->second.in_flight;
  UnitAssignment a{{job.record.id, unit->tile, unit->batch, unit->pass}, attempt, job.record.request};
  if (unit->pass > 0 && job.allocation)
    for (const PassSamples& n : job.allocation->tile(unit->tile)) a.samples_per_pass.emplace_back(n.even, n.odd);
  return a;
}

// Among `chosen`'s group at its priority, the job whose next unit has the
// lowest pass; the earliest submitted on a tie (set_group).
Job& Scheduler::lowest_pass_in_group(Job& chosen) {
  Job* pick = &chosen;
  int pick_pass = next_pass(chosen);
  for (Job* job : book_.runnable) {
    if (job->group != chosen.group || job->record.priority != chosen.record.priority || !job->has_work()) continue;
    const int pass = next_pass(*job);
    if (pass < pick_pass) {
      pick = job;
      pick_pass = pass;
    }
  }
  return *pick;
}

// Fair share among the tenants of the highest priority that has work.  A
// tenant is a job, or a group's jobs of one priority (a timelapse's frames
// share out as one: lowest_pass_in_group).  The tenant with the fewest units
// in flight is served, so N tenants each get about 1/N of the workers
// whatever their sizes, and a small job submitted behind a huge one finishes
// in about the time it would take alone on its share; ties go to the tenant
// handed the fewest units so far, then to the earliest submitted.  One scan
// of the runnable jobs, which also drops the finished ones from it.
Job* Scheduler::fair_choice() {
  struct Tenant {
    const std::string* group;  // nullptr: a job alone
    int priority;
    int in_flight = 0;
    std::uint64_t dispatched = 0;
    Job* first_with_work = nullptr;  // earliest submitted (groups: lowest_pass_in_group picks among them)
  };
  auto better = [](const Tenant& a, const Tenant& b) {
    if (a.priority != b.priority) return a.priority > b.priority;
    if (a.in_flight != b.in_flight) return a.in_flight < b.in_flight;
    if (a.dispatched != b.dispatched) return a.dispatched < b.dispatched;
    return a.first_with_work->record.sequence < b.first_with_work->record.sequence;
  };
  std::optional<Tenant> best;
  std::vector<Tenant> groups;  // few: timelapses in progress
  std::size_t kept = 0;
  for (std::size_t i = 0; i < book_.runnable.size(); ++i) {
    Job* job = book_.runnable[i];
    if (is_terminal(job->record.state)) continue;  // finished: dropped
    book_.runnable[kept++] = job;
    const bool work = job->has_work();
    if (job->group.empty()) {
      if (!work) continue;
      Tenant t{nullptr, job->record.priority, job->in_flight, job->dispatched, job};
      if (!best || better(t, *best)) best = t;
      continue;
    }
    // A group's units in flight count whether or not the frame has work left.
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Tenant& t) {
      return *t.group == job->group && t.priority == job->record.priority;
    });
    if (g == groups.end()) {
      groups.push_back(Tenant{&job->group, job->record.priority});
      g = groups.end() - 1;
    }
    g->in_flight += job->in_flight;
    g->dispatched += job->dispatched;
    if (work && !g->first_with_work) g->first_with_work = job;
  }
  book_.runnable.resize(kept);
  for (const Tenant& g : groups)
    if (g.first_with_work && (!best || better(g, *best))) best = g;
  return best ? best->first_with_work : nullptr;
}

std::vector<std::pair<std::string, std::uint64_t>> Scheduler::take_cancelled_attempts() {
  std::vector<std::pair<std::string, std::uint64_t>> out;
  out.swap(book_.cancelled);
  return out;
}

nlohmann::json Scheduler::workers() const {
  nlohmann::json out = nlohmann::json::array();
  const auto now = Clock::now();
  for (const auto& [id, w] : book_.workers) {
    auto field = [&info = w.info](const char* name) {
      return info.contains(name) ? info[name] : nlohmann::json(nullptr);
    };
    out.push_back({{"id", id},
                   {"cores", field("cores")},
                   {"slots", field("slots")},
                   {"version", field("version")},
                   {"units_done", w.units_done},
                   {"units_in_flight", w.in_flight},
                   {"draining", book_.drained_workers.contains(id)},
                   {"last_seen_s", std::chrono::duration<double>(now - w.last_seen).count()}});
  }
  return out;
}

bool Scheduler::set_draining(const std::string& worker_id, bool draining) {
  if (!book_.workers.contains(worker_id)) return false;
  if (draining) book_.drained_workers.insert(worker_id);
  else book_.drained_workers.erase(worker_id);
  return true;
}

void Scheduler::requeue_late(Clock::time_point now) {
  const auto limit = std::chrono::duration<double>(book_.limits.unit_timeout_s);
  std::vector<std::uint64_t> late;
  for (const auto& [a, f] : book_.in_flight)
    if (now - f.since > limit) late.push_back(a);
  for (auto a : late) book_.requeue(a, true);
}

}  // namespace skyfarm::server

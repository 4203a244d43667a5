#include "server/probes/probe_service.h"

#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <set>

#include "api/probe_answer.h"
#include "api/probe_spec.h"
#include "common/render/probe_units.h"

namespace skyfarm::server {
namespace {

enum class ProbeState { kRunning, kDone, kFailed, kClosed };

struct Probe {
  Probe(std::string probe_id, const api::ProbeRequest& r, const ProbePlan& p)
      : id(std::move(probe_id)), request(r), text(api::canonical_text(r)), reduction(p) {}

  std::string id;
  api::ProbeRequest request;
  std::string text;  // canonical: what every unit carries
  ProbeReduction reduction;
  ProbeState state = ProbeState::kRunning;
  std::string failure;
  std::size_t cursor = 0;                // next never-dispatched unit
  std::deque<std::size_t> requeued;      // units to dispatch again
  std::map<std::size_t, std::set<std::string>> failed_workers;

  const ProbePlan& plan() const { return reduction.plan(); }
  // The next unit to dispatch, or nullopt.
  std::optional<std::size_t> take_unit() {
    while (!requeued.empty()) {
      const std::size_t u = requeued.front();
      requeued.pop_front();
      if (!reduction.has(u)) return u;
    }
    while (cursor < plan().unit_count()) {
      const std::size_t u = cursor++;
      if (!reduction.has(u)) return u;
    }
    return std::nullopt;
  }
};

struct InFlight {
  std::string probe;
  std::size_t unit = 0;
  std::string worker;
  Clock::time_point since;
};

std::string unit_text(std::size_t unit) { return "probe unit " + std::to_string(unit); }

}  // namespace

struct ProbeService::Impl {
  ProbeLimits limits;
  mutable std::mutex mu;
  std::condition_variable changed;
  std::map<std::string, std::shared_ptr<Probe>> probes;
  std::deque<std::string> order;  // FIFO of running probes
  std::map<std::uint64_t, InFlight> in_flight;
  std::uint64_t next_attempt = kProbeAttemptBit | 1;
  std::uint64_t next_id = 1;
  std::vector<std::pair<std::string, std::uint64_t>> cancelled;
  std::set<std::string> workers;  // connected workers that run probe units
  bool closed = false;
  ProbeStats counters;

  // Under mu.
  void requeue(std::uint64_t attempt, bool tell_worker);
  void drop_attempts_of(const Probe& probe);
  void fail(Probe& probe, const std::string& message);
  void count_failure(Probe& probe, std::size_t unit, const std::string& worker, const std::string& message);
  void remove(const std::string& id);
};

void ProbeService::Impl::requeue(std::uint64_t attempt, bool tell_worker) {
  const auto it = in_flight.find(attempt);
  if (it == in_flight.end()) return;
  const InFlight f = it->second;
  in_flight.erase(it);
  if (tell_worker) cancelled.emplace_back(f.worker, attempt);
  const auto p = probes.find(f.probe);
  if (p == probes.end() || p->second->state != ProbeState::kRunning || p->second->reduction.has(f.unit)) return;
  p->second->requeued.push_back(f.unit);
  ++counters.requeues;
}

void ProbeService::Impl::drop_attempts_of(const Probe& probe) {
  for (auto it = in_flight.begin(); it != in_flight.end();) {
    if (it->second.probe == probe.id) {
      cancelled.emplace_back(it->second.worker, it->first);
      it = in_flight.erase(it);
    } else {
      ++it;
    }
  }
}

void ProbeService::Impl::fail(Probe& probe, const std::string& message) {
  drop_attempts_of(probe);
  probe.state = ProbeState::kFailed;
  probe.failure = message;
  changed.notify_all();
}

void ProbeService::Impl::count_failure(Probe& probe, std::size_t unit, const std::string& worker,
                                       const std::string& message) {
  ++counters.unit_failures;
  auto& failed = probe.failed_workers[unit];
  failed.insert(worker);
  if (static_cast<int>(failed.size()) >= limits.max_unit_failures)
    fail(probe, unit_text(unit) + " failed on " + std::to_string(failed.size()) + " workers; last error: " + message);
  else
    probe.requeued.push_back(unit);
}

void ProbeService::Impl::remove(const std::string& id) {
  if (const auto it = probes.find(id); it != probes.end()) drop_attempts_of(*it->second);
  probes.erase(id);
  std::erase(order, id);
}

ProbeService::ProbeService(ProbeLimits limits) : impl_(std::make_unique<Impl>()) { impl_->limits = limits; }
ProbeService::~ProbeService() = default;

// --- HTTP side ------------------------------------------------------------------

nlohmann::json ProbeService::run(const api::ProbeRequest& request, std::chrono::milliseconds timeout) {
  if (request.method != api::Method::kPath) throw std::invalid_argument("ProbeService runs path-traced probes only");
  const ProbeSpec spec = api::probe_spec(request);
  const ProbePlan plan = probe_plan(spec);
  std::unique_lock lock(impl_->mu);
  if (impl_->closed) throw NoProbeWorkers("the server is shutting down");
  if (impl_->workers.empty()) {
    ++impl_->counters.no_workers;
    throw NoProbeWorkers("no worker that runs probe units is connected");
  }
  if (static_cast<int>(impl_->probes.size()) >= impl_->limits.max_active_probes) {
    ++impl_->counters.refused_capacity;
    throw CapacityExceeded("the farm is tracing " + std::to_string(impl_->probes.size()) +
                           " probes, its limit; retry later");
  }
  const std::string id = "probe-" + std::to_string(impl_->next_id++);
  const auto probe = std::make_shared<Probe>(id, request, plan);
  impl_->probes.emplace(id, probe);
  impl_->order.push_back(id);
  ++impl_->counters.submitted;
  const bool answered =
      impl_->changed.wait_for(lock, timeout, [&] { return probe->state != ProbeState::kRunning; });
  impl_->remove(id);  // cancels what is still out when it timed out or failed
  if (!answered) {
    ++impl_->counters.timed_out;
    throw ProbeTimedOut("the probe was not answered within " + std::to_string(timeout.count() / 1000.0) +
                        " s (" + std::to_string(probe->reduction.received()) + " of " +
                        std::to_string(plan.unit_count()) + " units back); its units were cancelled");
  }
  if (probe->state == ProbeState::kClosed) throw NoProbeWorkers("the server is shutting down");
  if (probe->state == ProbeState::kFailed) {
    ++impl_->counters.failed;
    throw ProbeFailed(probe->failure);
  }
  ++impl_->counters.done;
  lock.unlock();
  const ProbeResult result = probe->reduction.result(request.wavelengths_nm.size());
  return api::probe_answer_json(request, path_probe_answer(spec, result));
}

void ProbeService::close() {
  const std::lock_guard lock(impl_->mu);
  impl_->closed = true;
  for (auto& [id, probe] : impl_->probes) {
    if (probe->state != ProbeState::kRunning) continue;
    impl_->drop_attempts_of(*probe);
    probe->state = ProbeState::kClosed;
  }
  impl_->changed.notify_all();
}

ProbeStats ProbeService::stats() const {
  const std::lock_guard lock(impl_->mu);
  ProbeStats s = impl_->counters;
  s.active = impl_->probes.size();
  s.units_in_flight = impl_->in_flight.size();
  s.workers = impl_->workers.size();
  for (const auto& [id, p] : impl_->probes)
    if (p->state == ProbeState::kRunning)
      s.queue_units += p->requeued.size() + (p->plan().unit_count() - p->cursor);
  return s;
}

// --- Broker side ----------------------------------------------------------------

void ProbeService::worker_joined(const std::string& worker_id, const nlohmann::json& info) {
  const auto caps = info.find("capabilities");
  const bool probes = caps != info.end() && caps->is_object() && caps->contains("probe") &&
                      (*caps)["probe"] == api::kProbeUnitsVersion;
  const std::lock_guard lock(impl_->mu);
  if (probes) impl_->workers.insert(worker_id);
  else impl_->workers.erase(worker_id);
}

void ProbeService::worker_left(const std::string& worker_id) {
  const std::lock_guard lock(impl_->mu);
  std::vector<std::uint64_t> attempts;
  for (const auto& [a, f] : impl_->in_flight)
    if (f.worker == worker_id) attempts.push_back(a);
  for (const auto a : attempts) impl_->requeue(a, false);
  impl_->workers.erase(worker_id);
}

std::optional<UnitAssignment> ProbeService::next_unit(const std::string& worker_id) {
  const std::lock_guard lock(impl_->mu);
  if (!impl_->workers.count(worker_id)) return std::nullopt;
  for (const auto& id : impl_->order) {
    Probe& probe = *impl_->probes.at(id);
    if (probe.state != ProbeState::kRunning) continue;
    const std::optional<std::size_t> unit = probe.take_unit();
    if (!unit) continue;
    const std::uint64_t attempt = impl_->next_attempt++;
    impl_->in_flight[attempt] = InFlight{id, *unit, worker_id, Clock::now()};
    ++impl_->counters.units_dispatched;
    return UnitAssignment{UnitKey{id, static_cast<int>(*unit), 0, 0}, attempt, probe.text, api::UnitKind::kProbe};
  }
  return std::nullopt;
}

void ProbeService::unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                             const std::vector<std::uint8_t>& bytes, std::uint64_t) {
  const std::lock_guard lock(impl_->mu);
  const auto it = impl_->in_flight.find(attempt);
  // A superseded attempt, or one of a probe that is over: dropped.
  if (it == impl_->in_flight.end() || it->second.probe != key.job_id ||
      it->second.unit != static_cast<std::size_t>(key.tile))
    return;
  const InFlight f = it->second;
  impl_->in_flight.erase(it);
  const auto p = impl_->probes.find(f.probe);
  if (p == impl_->probes.end() || p->second->state != ProbeState::kRunning) return;
  Probe& probe = *p->second;
  try {
    const ProbeUnitSums sums = ProbeUnitSums::deserialize(bytes, probe.plan());
    if (sums.unit.index != f.unit) throw ProbeUnitDecodeError("the sums are for another unit");
    if (probe.reduction.add(sums)) {
      ++impl_->counters.units_done;
      impl_->counters.paths += sums.counters.paths;
    }
  } catch (const std::exception& e) {  // ProbeUnitDecodeError, or sums that do not fit the plan
    impl_->count_failure(probe, f.unit, worker_id, std::string("its result could not be read: ") + e.what());
    return;
  }
  if (probe.reduction.complete()) {
    probe.state = ProbeState::kDone;
    impl_->changed.notify_all();
  }
}

void ProbeService::unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                               const std::string& message) {
  const std::lock_guard lock(impl_->mu);
  const auto it = impl_->in_flight.find(attempt);
  if (it == impl_->in_flight.end() || it->second.probe != key.job_id) return;
  const InFlight f = it->second;
  impl_->in_flight.erase(it);
  const auto p = impl_->probes.find(f.probe);
  if (p == impl_->probes.end() || p->second->state != ProbeState::kRunning) return;
  impl_->count_failure(*p->second, f.unit, worker_id, message);
}

std::vector<std::pair<std::string, std::uint64_t>> ProbeService::take_cancelled_attempts() {
  const std::lock_guard lock(impl_->mu);
  std::vector<std::pair<std::string, std::uint64_t>> out;
  out.swap(impl_->cancelled);
  return out;
}

void ProbeService::check_timeouts(Clock::time_point now) {
  const std::lock_guard lock(impl_->mu);
  const auto limit = std::chrono::duration<double>(impl_->limits.unit_timeout_s);
  std::vector<std::uint64_t> late;
  for (const auto& [a, f] : impl_->in_flight)
    if (now - f.since > limit) late.push_back(a);
  for (const auto a : late) impl_->requeue(a, true);
}

}  // namespace skyfarm::server

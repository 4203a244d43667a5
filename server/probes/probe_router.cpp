#include "server/probes/probe_router.h"

#include <algorithm>

namespace skyfarm::server {

ProbeRouter::ProbeRouter(ProbeService& probes, BrokerBackend& renders, int cycle)
    : probes_(probes), renders_(renders), cycle_(std::max(1, cycle)) {}

void ProbeRouter::worker_joined(const std::string& worker_id, const nlohmann::json& info) {
  renders_.worker_joined(worker_id, info);
  probes_.worker_joined(worker_id, info);
}

void ProbeRouter::worker_left(const std::string& worker_id) {
  renders_.worker_left(worker_id);
  probes_.worker_left(worker_id);
}

std::optional<UnitAssignment> ProbeRouter::next_unit(const std::string& worker_id) {
  const bool renders_first = cycle_ > 1 && turn_ % static_cast<std::uint64_t>(cycle_) == static_cast<std::uint64_t>(cycle_ - 1);
  BrokerBackend& first = renders_first ? renders_ : static_cast<BrokerBackend&>(probes_);
  BrokerBackend& second = renders_first ? static_cast<BrokerBackend&>(probes_) : renders_;
  std::optional<UnitAssignment> unit = first.next_unit(worker_id);
  if (!unit) unit = second.next_unit(worker_id);
  if (unit) ++turn_;
  return unit;
}

void ProbeRouter::unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                            const std::vector<std::uint8_t>& bytes, std::uint64_t paths) {
  owner_of(attempt).unit_done(worker_id, key, attempt, bytes, paths);
}

void ProbeRouter::unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                              const std::string& message) {
  owner_of(attempt).unit_failed(worker_id, key, attempt, message);
}

std::vector<std::pair<std::string, std::uint64_t>> ProbeRouter::take_cancelled_attempts() {
  auto out = renders_.take_cancelled_attempts();
  auto more = probes_.take_cancelled_attempts();
  out.insert(out.end(), more.begin(), more.end());
  return out;
}

void ProbeRouter::check_timeouts(Clock::time_point now) {
  renders_.check_timeouts(now);
  probes_.check_timeouts(now);
}

}  // namespace skyfarm::server

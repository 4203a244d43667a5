// What the ZeroMQ broker (broker.h) needs of the farm's jobs: implemented by
// JobService (jobs/job_service.h) for render units, behind ProbeRouter
// (probes/probe_router.h) which serves probe units; tests fake it.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/jobs/unit_assignment.h"

namespace skyfarm::server {

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

}  // namespace skyfarm::server

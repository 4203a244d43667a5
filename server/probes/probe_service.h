// Path-traced radiance probes through the farm (POST /v1/sky/radiance with
// "method": "path"): a probe is cut into units
// (probe_plan, common/render/probe_answer.h), the units go to the
// workers through the ZeroMQ broker next to render units (ProbeRouter,
// probe_router.h, asks this service first), and their sums are reduced here
// in canonical order, so the answer is the same document, number for
// number, as `skyfarm-worker probe` of the same request, whatever the
// number of workers and the order results arrive in.
//
// run() is synchronous: the HTTP thread submits the probe and waits for its
// answer.  Units are handed out FIFO over probes, each probe's in unit
// order, only to workers whose READY capabilities hold "probe":
// api::kProbeUnitsVersion.  Like render units (job_service.h) every dispatch
// has its own attempt; a unit whose worker is lost, or that is not back
// after unit_timeout_s, is dispatched again (results of superseded attempts
// are dropped); a unit that fails (or whose result cannot be decoded) on
// max_unit_failures distinct workers fails the probe with the last
// worker's message.  Attempt numbers carry kProbeAttemptBit, so the broker
// (and the router) can tell probe attempts from the JobService's, which
// count up from 1.
//
// Parameters (ProbeLimits)
//   unit_timeout_s      a dispatched unit with no result after this is
//                       dispatched again (skyfarm-server: the smaller of
//                       --unit-timeout and kProbeUnitTimeoutCapS, as a probe
//                       unit is 0.2-2 s of work and a client is waiting)
//   max_unit_failures   distinct workers failing one unit fail the probe (3)
//   max_active_probes   probes waiting for their answer at once; one more is
//                       refused with CapacityExceeded (16; each holds an
//                       HTTP thread while it waits)
//
// Thread-safe (one mutex); the broker thread and HTTP threads call in.
#pragma once
#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/probe_request.h"
#include "server/broker/broker_backend.h"
#include "server/jobs/job_errors.h"

namespace skyfarm::server {

inline constexpr std::uint64_t kProbeAttemptBit = std::uint64_t{1} << 63;
inline bool is_probe_attempt(std::uint64_t attempt) { return (attempt & kProbeAttemptBit) != 0; }
inline constexpr double kProbeUnitTimeoutCapS = 30.0;

struct ProbeLimits {
  double unit_timeout_s = 120.0;
  int max_unit_failures = 3;
  int max_active_probes = 16;
};

// Why run() has no answer (the HTTP layer maps each to its status).
struct NoProbeWorkers : std::runtime_error {  // 503: no connected worker runs probe units
  using std::runtime_error::runtime_error;
};
struct ProbeTimedOut : std::runtime_error {  // 504: not answered in time (its units were cancelled)
  using std::runtime_error::runtime_error;
};
struct ProbeFailed : std::runtime_error {  // 502: a unit failed on max_unit_failures workers
  using std::runtime_error::runtime_error;
};

// Counters since construction and gauges (for /metrics).
struct ProbeStats {
  std::uint64_t submitted = 0, done = 0, failed = 0, timed_out = 0, no_workers = 0, refused_capacity = 0;
  std::uint64_t units_dispatched = 0, units_done = 0, unit_failures = 0, requeues = 0, paths = 0;
  std::uint64_t active = 0, queue_units = 0, units_in_flight = 0, workers = 0;  // gauges
};

class ProbeService final : public BrokerBackend {
 public:
  explicit ProbeService(ProbeLimits limits = {});
  ~ProbeService() override;
  ProbeService(const ProbeService&) = delete;
  ProbeService& operator=(const ProbeService&) = delete;

  // Traces a "path" probe on the farm and returns its answer document
  // (api/probe_answer.h).
  // Throws NoProbeWorkers, CapacityExceeded, ProbeTimedOut, ProbeFailed, or
  // std::invalid_argument for a "lut" probe.
  nlohmann::json run(const api::ProbeRequest& request, std::chrono::milliseconds timeout);
  // Server shutdown: waiting probes stop waiting (NoProbeWorkers), their
  // units are cancelled, and new ones are refused alike.
  void close();
  ProbeStats stats() const;

  // BrokerBackend (the ProbeRouter forwards the probe's share).
  void worker_joined(const std::string& worker_id, const nlohmann::json& info) override;
  void worker_left(const std::string& worker_id) override;
  std::optional<UnitAssignment> next_unit(const std::string& worker_id) override;
  void unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                 const std::vector<std::uint8_t>& bytes, std::uint64_t paths) override;
  void unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                   const std::string& message) override;
  std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts() override;
  void check_timeouts(Clock::time_point now) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skyfarm::server

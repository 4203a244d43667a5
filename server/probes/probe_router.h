// The broker's backend when radiance probes share the farm with renders:
// the ProbeService (probe_service.h) and the JobService (or any
// BrokerBackend) behind one BrokerBackend.
//
//   next_unit    probes are small and a client waits for each, so they do
//                not queue behind renders: while both have work, of every
//                `cycle` units handed out `cycle - 1` are asked of the
//                probes first and one of the renders first (default 4: 3
//                probe units to 1 render unit), so a large probe cannot
//                starve the renders either; whoever has no work passes.
//   results      unit_done / unit_failed go to whichever service owns the
//                attempt (probe attempts carry kProbeAttemptBit).
//   the rest     worker_joined / worker_left / check_timeouts go to both;
//                take_cancelled_attempts is the two lists together.
// Called by the broker thread only (next_unit keeps the turn unlocked).
#pragma once
#include <cstdint>

#include "server/broker/broker_backend.h"
#include "server/probes/probe_service.h"

namespace skyfarm::server {

class ProbeRouter final : public BrokerBackend {
 public:
  ProbeRouter(ProbeService& probes, BrokerBackend& renders, int cycle = 4);

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
  BrokerBackend& owner_of(std::uint64_t attempt) { return is_probe_attempt(attempt) ? probes_ : renders_; }

  ProbeService& probes_;
  BrokerBackend& renders_;
  int cycle_;
  std::uint64_t turn_ = 0;  // units handed out
};

}  // namespace skyfarm::server

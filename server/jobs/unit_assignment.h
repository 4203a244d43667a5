// A unit of work as the broker hands it to a worker: which job, tile,
// wavelength batch and pass, under which attempt id.  Shared by the job
// service (which makes them) and the broker (which sends them).
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "api/wire.h"

namespace skyfarm::server {

using Clock = std::chrono::steady_clock;

struct UnitKey {
  std::string job_id;
  int tile = 0, batch = 0, pass = 0;
  bool operator==(const UnitKey&) const = default;
};

// What the broker sends to a worker for one unit.
struct UnitAssignment {
  UnitKey key;
  std::uint64_t attempt = 0;       // unique per dispatch; results of other attempts are dropped
  std::string request_canonical;   // api::canonical_text of the job's request (workers cache the setup per job)
  api::UnitKind kind = api::UnitKind::kRender;  // kProbe: a radiance probe's unit (server/probes/probe_service.h)
  // An adaptive job's samples per pass after its pilot, per allocation block
  // of the tile, (even, odd) pixels (api::UnitMsg); empty: uniform.
  std::vector<std::pair<int, int>> samples_per_pass{};
};

}  // namespace skyfarm::server

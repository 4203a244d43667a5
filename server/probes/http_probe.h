// POST /v1/sky/radiance with "method": "path": the
// probe traced on the farm (server/probes/probe_service.h); the request waits for
// the answer.
//
// Limits on the server (else 400 naming the field):
//   directions x wavelengths     at most kMaxFarmProbePairs   ("directions")
//   samples x that               at most kMaxFarmProbePaths   ("samples")
// Answers
//   200  the probe's answer (api/probe_answer.h), the same document, number
//        for number, as `skyfarm-worker probe` of the same body; header
//        Server-Timing: probe;dur=<milliseconds on the farm>
//   429  the server already waits for max_active_probes probes (Retry-After)
//   502  a unit failed on 3 workers: detail = the workers' last message
//   503  no connected worker runs probe units (Retry-After: 5)
//   504  not answered within the server's --probe-timeout; its units are
//        cancelled (retry with fewer samples, or run skyfarm-worker probe)
#pragma once
#include <chrono>
#include <cstdint>

#include "api/probe_request.h"

namespace httplib {
struct Response;
}

namespace skyfarm::server {

class ProbeService;

inline constexpr std::uint64_t kMaxFarmProbePairs = 100000;
inline constexpr double kMaxFarmProbePaths = 1e9;
inline constexpr int kNoProbeWorkersRetryAfterS = 5;

// Throws api::ValidationError when the probe is too large for the server.
void check_farm_probe_limits(const api::ProbeRequest& request);

// Runs a "path" probe on the farm and writes the answer (or throws the
// HttpError of the problem).  `probes` may be null (no farm): 503.
void answer_farm_probe(ProbeService* probes, const api::ProbeRequest& request, std::chrono::milliseconds timeout,
                       httplib::Response& res);

}  // namespace skyfarm::server

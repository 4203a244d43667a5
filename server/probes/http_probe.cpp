#include "server/probes/http_probe.h"

#include <httplib.h>

#include <cstdio>

#include "api/field_error.h"
#include "server/http/http_problem.h"
#include "server/probes/probe_service.h"

namespace skyfarm::server {
namespace {

HttpError problem(int status, std::string_view type, std::string title, std::string detail) {
  Problem p;
  p.status = status;
  p.type = std::string(type);
  p.title = std::move(title);
  p.detail = std::move(detail);
  if (status == 503) p.headers.emplace_back("Retry-After", std::to_string(kNoProbeWorkersRetryAfterS));
  return HttpError(std::move(p));
}

}  // namespace

void check_farm_probe_limits(const api::ProbeRequest& request) {
  const auto pairs = static_cast<std::uint64_t>(request.directions.size() * request.wavelengths_nm.size());
  if (pairs > kMaxFarmProbePairs)
    throw api::ValidationError({api::FieldError{
        "directions", "directions x wavelengths must be at most 100000 with method path on the server",
        std::to_string(pairs)}});
  if (static_cast<double>(pairs) * static_cast<double>(request.samples) > kMaxFarmProbePaths)
    throw api::ValidationError({api::FieldError{
        "samples", "samples x directions x wavelengths must be at most 1e9 on the server (use skyfarm-worker probe)",
        std::to_string(request.samples)}});
}

void answer_farm_probe(ProbeService* probes, const api::ProbeRequest& request, std::chrono::milliseconds timeout,
                       httplib::Response& res) {
  check_farm_probe_limits(request);
  if (!probes)
    throw problem(503, kProblemNoProbeWorkers, "No probe workers", "this server traces probes on no farm");
  const auto t0 = std::chrono::steady_clock::now();
  nlohmann::json answer;
  try {
    answer = probes->run(request, timeout);
  } catch (const NoProbeWorkers& e) {
    throw problem(503, kProblemNoProbeWorkers, "No probe workers",
                  std::string(e.what()) + "; retry when workers have joined");
  } catch (const ProbeTimedOut& e) {
    throw problem(504, kProblemProbeTimeout, "The probe timed out", e.what());
  } catch (const ProbeFailed& e) {
    throw problem(502, kProblemProbeFailed, "The probe failed on the workers", e.what());
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  char timing[64];
  std::snprintf(timing, sizeof timing, "probe;dur=%.1f", ms);
  res.set_header("Server-Timing", timing);
  send_json(res, 200, answer);
}

}  // namespace skyfarm::server

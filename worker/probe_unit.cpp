#include "worker/probe_unit.h"

#include <chrono>
#include <stdexcept>

#include "api/field_error.h"
#include "api/probe_spec.h"
#include "common/render/probe_answer.h"

namespace skyfarm {

ProbeSetup make_probe_setup(const std::string& request_text) {
  try {
    api::ProbeRequest request = api::parse_probe_request(request_text);
    if (request.method != api::Method::kPath) throw std::runtime_error("probe units are path traced; method is lut");
    ProbeSpec spec = api::probe_spec(request);
    Scene scene = probe_scene(spec);
    const ProbePlan plan = probe_plan(spec);
    std::shared_ptr<const RadianceControl> control = probe_roulette_control(spec, scene);
    return ProbeSetup{std::move(request), std::move(scene), std::move(spec.directions), plan, std::move(control)};
  } catch (const api::ValidationError& e) {
    throw std::runtime_error(std::string("invalid probe request: ") + e.what());
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("cannot set up the probe: ") + e.what());
  }
}

api::Message run_probe_unit(const ProbeSetup& setup, const api::UnitMsg& task) {
  const auto t0 = std::chrono::steady_clock::now();
  const api::UnitRef& u = task.unit;
  try {
    if (static_cast<std::size_t>(u.tile) >= setup.plan.unit_count() || u.batch != 0 || u.pass != 0)
      throw std::runtime_error("probe unit " + std::to_string(u.tile) + " is outside the probe's " +
                               std::to_string(setup.plan.unit_count()) + " units");
    const ProbeUnitSums sums = trace_probe_unit(setup.scene, setup.directions, setup.request.wavelengths_nm,
                                                setup.request.seed, setup.plan.unit(static_cast<std::size_t>(u.tile)),
                                                setup.control);
    const std::vector<std::uint8_t> bytes = sums.serialize();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return api::ResultMsg{u, sums.counters.paths, seconds, std::string(bytes.begin(), bytes.end())};
  } catch (const std::exception& e) {
    return api::FailedMsg{u, e.what()};
  }
}

}  // namespace skyfarm

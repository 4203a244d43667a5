#include "common/render/probe_answer.h"

#include <algorithm>

#include "common/lut/lut_probe.h"
#include "common/render/render_plan.h"
#include "common/sun/sun.h"

namespace skyfarm {
namespace {

constexpr std::size_t kMaxUnits = kProbeDefaultMaxUnits;
constexpr std::size_t kMinUnits = 64;
constexpr std::size_t kUnitTextBudgetBytes = std::size_t{256} << 20;

}  // namespace

Scene probe_scene(const ProbeSpec& spec) {
  const auto [lmin, lmax] = std::minmax_element(spec.wavelengths_nm.begin(), spec.wavelengths_nm.end());
  // The majorant grid must cover every asked wavelength; 1 nm margin.
  return Scene::from_specs(spec.atmosphere, spec.sun, spec.location, spec.time, *lmin - 0.5, *lmax + 0.5);
}

ProbePlan probe_plan(const ProbeSpec& spec) {
  const std::size_t text = std::max<std::size_t>(1, spec.unit_text_bytes);
  const std::size_t max_units = std::clamp(kUnitTextBudgetBytes / text, kMinUnits, kMaxUnits);
  return ProbePlan::make(spec.directions.size() * spec.wavelengths_nm.size(),
                         static_cast<std::uint64_t>(spec.samples), max_units);
}

std::shared_ptr<const RadianceControl> probe_roulette_control(const ProbeSpec& spec, const Scene& scene) {
  if (spec.lut || !roulette_control_pays(scene.sun().zenith_deg())) return nullptr;
  return std::make_shared<const RadianceControl>(scene);
}

ProbeAnswer path_probe_answer(const ProbeSpec& spec, const ProbeResult& result) {
  const Sun sun = Sun::from_spec(spec.sun, spec.location, spec.time);
  return ProbeAnswer{result.radiance, result.standard_error, result.counters.nonfinite, sun.zenith_deg(),
                     sun.azimuth_deg()};
}

ProbeAnswer answer_probe(const ProbeSpec& spec, int threads) {
  const Scene scene = probe_scene(spec);
  if (spec.lut)
    return ProbeAnswer{probe_radiance_lut(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(),
                                          spec.directions, spec.wavelengths_nm, scene.refraction() != nullptr),
                       std::nullopt, 0, scene.sun().zenith_deg(), scene.sun().azimuth_deg()};
  const ProbeResult r = probe_radiance(scene, spec.directions, spec.wavelengths_nm, probe_plan(spec), spec.seed,
                                       threads, probe_roulette_control(spec, scene));
  return path_probe_answer(spec, r);
}

}  // namespace skyfarm

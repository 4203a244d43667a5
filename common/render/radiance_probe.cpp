#include "common/render/radiance_probe.h"

#include <algorithm>
#include <stdexcept>

#include "common/render/parallel.h"
#include "common/render/probe_units.h"

namespace skyfarm {

ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, int samples, std::uint64_t seed,
                           int threads) {
  const ProbePlan plan = ProbePlan::make(directions.size() * wavelengths_nm.size(),
                                         static_cast<std::uint64_t>(std::max(samples, 0)));
  return probe_radiance(scene, directions, wavelengths_nm, plan, seed, threads);
}

ProbeResult probe_radiance(const Scene& scene, const std::vector<glm::dvec3>& directions,
                           const std::vector<double>& wavelengths_nm, const ProbePlan& plan, std::uint64_t seed,
                           int threads, std::shared_ptr<const RadianceControl> control) {
  if (plan.pairs != directions.size() * wavelengths_nm.size())
    throw std::invalid_argument("probe_radiance: the plan is not for these directions and wavelengths");
  // One task per pair of each unit: the cells a farm worker traces in a row,
  // traced here in parallel (each cell's sum is the same either way).
  std::vector<ProbeUnitSums> cells(plan.chunks * plan.pairs);
  parallel_for(cells.size(), threads, [&](std::size_t task, int) {
    const std::size_t chunk = task / plan.pairs, pair = task % plan.pairs;
    ProbeUnit cell = plan.unit(chunk * plan.groups + pair / plan.pairs_per_unit);
    cell.pair_begin = pair;
    cell.pair_end = pair + 1;
    cells[task] = trace_probe_unit(scene, directions, wavelengths_nm, seed, cell, control);
  });
  // Regroup the cells into the plan's units and reduce them as the server does.
  ProbeReduction reduction(plan);
  for (std::size_t i = 0; i < plan.unit_count(); ++i) {
    ProbeUnitSums unit;
    unit.unit = plan.unit(i);
    for (std::size_t pair = unit.unit.pair_begin; pair < unit.unit.pair_end; ++pair) {
      const ProbeUnitSums& cell = cells[unit.unit.chunk * plan.pairs + pair];
      unit.sum.push_back(cell.sum[0]);
      unit.sum_sq.push_back(cell.sum_sq[0]);
      unit.counters.add(cell.counters);
    }
    reduction.add(unit);
  }
  return reduction.result(wavelengths_nm.size());
}

}  // namespace skyfarm

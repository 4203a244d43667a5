// The cost of a placed cloud volume (common/clouds/cloud_volume.h): building
// its brick majorants from a grid, one sigma_t look-up, and one
// for_each_majorant walk across the whole volume (the DDA a tracking step
// starts with).  A 128^3 grid of 25 m voxels, a third of it empty, yawed
// 30 degrees.  Not a test; run with
//   build/tests/skyfarm_bench --benchmark_filter=CloudVolume --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
// and report the medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>

#include <glm/geometric.hpp>

#include "common/clouds/cloud_volume.h"

namespace skyfarm {
namespace {

constexpr double kRadius = 6'371'000.0;

std::shared_ptr<const assets::VolumeGrid> grid(int n) {
  auto g = std::make_shared<assets::VolumeGrid>();
  g->size = glm::ivec3(n);
  g->voxel_size_m = glm::dvec3(25.0);
  g->origin_m = glm::dvec3(-12.5 * n, -12.5 * n, 0.0);
  g->values.resize(static_cast<std::size_t>(n) * n * n);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        // A ball of noisy density: the corners (about a third) are empty.
        const double r = glm::length(glm::dvec3(x, y, z) - glm::dvec3(0.5 * (n - 1))) / (0.5 * n);
        g->values[static_cast<std::size_t>(x) + n * (y + static_cast<std::size_t>(n) * z)] =
            r < 1.0 ? u(rng) : 0.0f;
      }
  g->max_value = 1.0f;
  return g;
}

Placement placement() {
  Placement p;
  p.translate_m = {0.0, 3000.0, 1000.0};
  p.rotate_deg = {30.0, 0.0, 0.0};
  return p;
}

void BM_CloudVolumeBuild(benchmark::State& state) {
  const auto g = grid(128);
  for (auto _ : state) {
    CloudVolume v(g, placement(), 0.05, CloudOptics{}, kRadius);
    benchmark::DoNotOptimize(v.brick_counts());
  }
  state.SetItemsProcessed(state.iterations() * 128 * 128 * 128);
}
BENCHMARK(BM_CloudVolumeBuild)->Unit(benchmark::kMillisecond);

void BM_CloudVolumeSigma(benchmark::State& state) {
  const CloudVolume v(grid(128), placement(), 0.05, CloudOptics{}, kRadius);
  const EnuFrame enu(kRadius);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.0, 127.0);
  std::vector<glm::dvec3> points(4096);
  for (auto& p : points) p = enu.to_world(v.enu_from_index({u(rng), u(rng), u(rng)}));
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(v.sigma_t(points[i++ & 4095]));
}
BENCHMARK(BM_CloudVolumeSigma);

void BM_CloudVolumeMajorantWalk(benchmark::State& state) {
  const CloudVolume v(grid(128), placement(), 0.05, CloudOptics{}, kRadius);
  const EnuFrame enu(kRadius);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Ray> rays(1024);
  const glm::dvec3 centre = v.enu_from_index(glm::dvec3(63.5));
  for (auto& r : rays) {
    const glm::dvec3 from = centre + 4000.0 * glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    r = {enu.to_world(from), glm::normalize(centre + 500.0 * glm::dvec3(u(rng), u(rng), u(rng)) - from)};
  }
  std::size_t i = 0, pieces = 0;
  for (auto _ : state) {
    v.for_each_majorant(rays[i++ & 1023], 0.0, 1e4, [&](double, double, double) {
      ++pieces;
      return true;
    });
  }
  state.counters["pieces_per_ray"] = static_cast<double>(pieces) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_CloudVolumeMajorantWalk);

}  // namespace
}  // namespace skyfarm

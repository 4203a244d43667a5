// Rays per second through TriangleBvh on a 1 M-triangle mesh (a 708 x 708
// quad heightfield of random hills, 2 km across), closest hit and occlusion,
// random rays from above the terrain aimed at random points of it; and the
// build time.  Single-threaded queries.  Not a test; run with
//   build/tests/skyfarm_bench --benchmark_filter=TriangleBvh --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
// and report the medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "common/accel/triangle_bvh.h"

namespace skyfarm::accel {
namespace {

constexpr int kQuads = 708;       // 2 * 708^2 = 1 002 528 triangles
constexpr double kSize = 2000.0;  // metres across

double height(double x, double y) {
  return 30.0 * std::sin(x * 0.011) * std::cos(y * 0.013) + 8.0 * std::sin(x * 0.07 + y * 0.05) +
         2.0 * std::sin(x * 0.31) * std::sin(y * 0.29);
}

MeshArrays heightfield() {
  MeshArrays m;
  const int n = kQuads + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = kSize * (i / double(kQuads) - 0.5), y = kSize * (j / double(kQuads) - 0.5);
      m.positions.emplace_back(x, y, height(x, y));
    }
  for (int j = 0; j < kQuads; ++j)
    for (int i = 0; i < kQuads; ++i) {
      const auto a = static_cast<std::uint32_t>(j * n + i), b = a + 1, c = a + n, d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, c, c, b, d});
    }
  return m;
}

const TriangleBvh& bvh() {
  static const TriangleBvh b({heightfield()}, {{0, glm::dmat4(1.0)}});
  return b;
}

struct Ray {
  glm::dvec3 o, d;
};

std::vector<Ray> rays(std::size_t n) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Ray> r;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 o{kSize * u(rng), kSize * u(rng), 60.0 + 200.0 * (u(rng) + 0.5)};
    const glm::dvec3 target{kSize * u(rng), kSize * u(rng), 0.0};
    r.push_back({o, glm::normalize(target - o)});
  }
  return r;
}

void BM_TriangleBvhBuild(benchmark::State& state) {
  const MeshArrays mesh = heightfield();
  for (auto _ : state) {
    const TriangleBvh b({mesh}, {{0, glm::dmat4(1.0)}}, {static_cast<unsigned>(state.range(0))});
    benchmark::DoNotOptimize(b.empty());
  }
}

void BM_TriangleBvhClosestHit(benchmark::State& state) {
  const TriangleBvh& b = bvh();
  const auto rs = rays(1 << 16);
  std::size_t i = 0, hits = 0;
  for (auto _ : state) {
    const Ray& r = rs[i++ & (rs.size() - 1)];
    hits += b.closest_hit(r.o, r.d, 1e30).has_value();
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["hit_fraction"] = double(hits) / double(state.iterations());
}

void BM_TriangleBvhOccluded(benchmark::State& state) {
  const TriangleBvh& b = bvh();
  const auto rs = rays(1 << 16);
  std::size_t i = 0, hits = 0;
  for (auto _ : state) {
    const Ray& r = rs[i++ & (rs.size() - 1)];
    hits += b.occluded(r.o, r.d, 1e30);
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

BENCHMARK(BM_TriangleBvhBuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TriangleBvhClosestHit);
BENCHMARK(BM_TriangleBvhOccluded);

}  // namespace
}  // namespace skyfarm::accel

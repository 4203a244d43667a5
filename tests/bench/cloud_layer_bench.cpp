// The cost of a procedural cloud layer (the fair-weather cumulus preset):
// one sigma_t evaluation (what each tentative collision pays), one
// for_each_majorant walk per kind of ray with the pieces it visits, and the
// majorants' tightness: integral of sigma_maj over integral of sigma_t along
// the ray, i.e. the mean number of tentative collisions per unit of real
// optical depth (1 would be a perfect bound).  Not a test; run with
//   build/tests/skyfarm_bench --benchmark_filter=CloudLayer --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
// and report the medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>

#include "common/clouds/cloud_layer.h"
#include "common/core/constants.h"
#include "common/sampling/sampler.h"

namespace skyfarm {
namespace {

constexpr double kR = kEarthRadius_m;

CloudLayerSpec cumulus(double coverage) {
  CloudLayerSpec s = cloud_layer_preset(CloudType::kCumulus);
  s.coverage = coverage;
  return s;
}

double u(std::uint64_t i, std::uint64_t dim) { return to_unit(hash_keys(99, i, dim, 0)); }

// kind 0: from the ground, upper hemisphere (cosine-weighted like a sky
// camera's average); 1: grazing, tangent inside the layer; 2: from 400 km
// towards the layer below.
std::vector<Ray> rays(const CloudLayerSpec& s, int kind, int n) {
  std::vector<Ray> out;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::uint64_t>(i);
    const double az = 2.0 * kPi * u(k, 0);
    const glm::dvec3 h{std::sin(az), std::cos(az), 0.0};
    if (kind == 0) {
      const double mu = std::sqrt(u(k, 1));
      out.push_back({glm::dvec3(5e4 * (u(k, 2) - 0.5), 5e4 * (u(k, 3) - 0.5), kR),
                     glm::normalize(h * std::sqrt(1.0 - mu * mu) + glm::dvec3(0, 0, mu))});
    } else if (kind == 1) {
      const double r = kR + s.base_m + s.thickness_m * u(k, 1);
      out.push_back({glm::dvec3(0, 0, r) - 2e5 * h, h});
    } else {
      const glm::dvec3 o = glm::normalize(glm::dvec3(0.1 * (u(k, 1) - 0.5), 0.1 * (u(k, 2) - 0.5), 1.0)) * (kR + 4e5);
      const glm::dvec3 target = glm::normalize(glm::dvec3(5e4 * (u(k, 3) - 0.5), 5e4 * (u(k, 4) - 0.5), kR)) *
                                (kR + s.base_m + 0.5 * s.thickness_m);
      out.push_back({o, glm::normalize(target - o)});
    }
  }
  return out;
}

void BM_CloudLayerSigmaT(benchmark::State& state) {
  const CloudLayerSpec s = cumulus(static_cast<double>(state.range(0)) / 100.0);
  const CloudLayer layer(s, kR, glm::dvec3(8.1e8 * 10.0, 0.0, 0.0));
  std::vector<glm::dvec3> points;
  for (std::uint64_t i = 0; i < 4096; ++i)
    points.push_back(glm::normalize(glm::dvec3(1e5 * (u(i, 0) - 0.5), 1e5 * (u(i, 1) - 0.5), kR)) *
                     (kR + s.base_m + s.thickness_m * u(i, 2)));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(layer.sigma_t(points[i]));
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CloudLayerSigmaT)->Arg(40)->Arg(100);

void BM_CloudLayerMajorants(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));
  const CloudLayerSpec s = cumulus(static_cast<double>(state.range(1)) / 100.0);
  const CloudLayer layer(s, kR, glm::dvec3(8.1e8 * 10.0, 0.0, 0.0));
  const std::vector<Ray> rs = rays(s, kind, 256);
  // Pieces per ray and tightness, once (not timed).
  double pieces = 0.0, majorant_tau = 0.0, tau = 0.0;
  for (const Ray& ray : rs) {
    layer.for_each_majorant(ray, 0.0, 1e7, [&](double t0, double t1, double sigma_maj) {
      pieces += 1.0;
      majorant_tau += sigma_maj * (t1 - t0);
      const int n = std::max(1, static_cast<int>(std::ceil((t1 - t0) / 10.0)));
      for (int j = 0; j < n; ++j) tau += layer.sigma_t(ray.at(t0 + (j + 0.5) * (t1 - t0) / n)) * (t1 - t0) / n;
      return true;
    });
  }
  std::size_t i = 0;
  for (auto _ : state) {
    double sum = 0.0;
    layer.for_each_majorant(rs[i], 0.0, 1e7, [&](double t0, double t1, double sigma_maj) {
      sum += sigma_maj * (t1 - t0);
      return true;
    });
    benchmark::DoNotOptimize(sum);
    i = (i + 1) & 255;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["pieces_per_ray"] = pieces / static_cast<double>(rs.size());
  state.counters["tentative_per_tau"] = tau > 0.0 ? majorant_tau / tau : 0.0;
  state.counters["tau_per_ray"] = tau / static_cast<double>(rs.size());
}
BENCHMARK(BM_CloudLayerMajorants)
    ->Args({0, 40})
    ->Args({1, 40})
    ->Args({2, 40})
    ->Args({0, 100})
    ->Args({1, 100})
    ->ArgNames({"kind", "coverage"});

void BM_CloudLayerBuild(benchmark::State& state) {
  const CloudLayerSpec s = cumulus(0.4);
  for (auto _ : state) benchmark::DoNotOptimize(CloudLayer(s, kR, glm::dvec3(0.0)));
}
BENCHMARK(BM_CloudLayerBuild)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace skyfarm

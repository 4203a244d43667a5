// The cost of one BSDF evaluation and one sample, single- vs multiple-bounce,
// per material kind (GGX, alpha 0.5, wo at 40 degrees): what a ground or an
// object with a rough surface adds to a path vertex; and of one
// multiple-bounce walk estimate, one-way vs two-way.  Not a test; run with
//   build/tests/skyfarm_bench --benchmark_filter=Bsdf --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
// and report the medians.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "common/material/bsdf.h"
#include "common/material/lambertian.h"
#include "common/material/microfacet_distribution.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/position_free_walk.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"

namespace skyfarm::material {
namespace {

enum Kind { kLambertian, kConductor, kConductorMulti, kDielectric, kDielectricMulti, kDiffuse, kDiffuseMulti };

std::unique_ptr<Bsdf> make(Kind kind) {
  const MicrofacetDistribution d(MicrofacetModel::ggx, 0.5, 0.5);
  const ConductorFresnel gold{{0.27, 2.78}, false};  // gold near 600 nm (Johnson & Christy 1972)
  switch (kind) {
    case kLambertian: return std::make_unique<Lambertian>(0.5);
    case kConductor: return std::make_unique<RoughConductor>(d, gold);
    case kConductorMulti: return std::make_unique<MultipleBounceBsdf>(d, Facet::conductor(gold));
    case kDielectric: return std::make_unique<RoughDielectric>(d, 1.33);
    case kDielectricMulti: return std::make_unique<MultipleBounceBsdf>(d, Facet::dielectric(1.33));
    case kDiffuse: return std::make_unique<RoughDiffuse>(d, 0.8);
    case kDiffuseMulti: return std::make_unique<MultipleBounceBsdf>(d, Facet::diffuse(0.8));
  }
  return nullptr;
}

const glm::dvec3 kWo{std::sin(0.7), 0.0, std::cos(0.7)};

void BM_BsdfEval(benchmark::State& state) {
  const auto bsdf = make(static_cast<Kind>(state.range(0)));
  RandomSequence rng(1234);
  double sum = 0.0;
  for (auto _ : state) {
    // A direction on the upper hemisphere that changes every call.
    const double u = rng.next(), v = rng.next();
    const double z = std::max(1e-3, u), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 6.283185307179586 * v;
    sum += bsdf->f(kWo, glm::dvec3(r * std::cos(phi), r * std::sin(phi), z), rng);
  }
  benchmark::DoNotOptimize(sum);
}

void BM_BsdfSample(benchmark::State& state) {
  const auto bsdf = make(static_cast<Kind>(state.range(0)));
  RandomSequence rng(4321);
  double sum = 0.0;
  for (auto _ : state) {
    const double uc = rng.next(), u0 = rng.next(), u1 = rng.next();
    if (const auto s = bsdf->sample(kWo, uc, {u0, u1}, rng)) sum += s->value;
  }
  benchmark::DoNotOptimize(sum);
}

// One multiple-bounce estimate of f |wo.z| by the one-way walk (estimator 0)
// or the two-way walk (estimator 1) that f() uses, per facet kind (0
// conductor (gold), 1 diffuse (albedo 0.8), 2 dielectric (eta 1.33)): the
// cost side of the two-way walk's variance reduction.
void BM_BsdfWalk(benchmark::State& state) {
  const MicrofacetDistribution d(MicrofacetModel::ggx, 0.5, 0.5);
  const Facet facets[] = {Facet::conductor(ConductorFresnel{{0.27, 2.78}, false}), Facet::diffuse(0.8),
                          Facet::dielectric(1.33)};
  const PositionFreeWalk walk(d, facets[state.range(0)], HeightCorrelation::correlated);
  const bool two_way = state.range(1) != 0;
  RandomSequence rng(2468);
  double sum = 0.0;
  for (auto _ : state) {
    const double u = rng.next(), v = rng.next();
    const double z = std::max(1e-3, u), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 6.283185307179586 * v;
    const glm::dvec3 wi(r * std::cos(phi), r * std::sin(phi), z);
    sum += two_way ? walk.estimate_bidirectional(wi, kWo, rng) : walk.estimate(wi, kWo, rng);
  }
  benchmark::DoNotOptimize(sum);
}

// 0 Lambertian, 1 conductor, 2 conductor multiple-bounce, 3 dielectric,
// 4 dielectric multiple-bounce, 5 rough diffuse, 6 rough diffuse multiple-bounce.
BENCHMARK(BM_BsdfEval)->DenseRange(0, 6);
BENCHMARK(BM_BsdfSample)->DenseRange(0, 6);
BENCHMARK(BM_BsdfWalk)->ArgsProduct({{0, 1, 2}, {0, 1}});

}  // namespace
}  // namespace skyfarm::material

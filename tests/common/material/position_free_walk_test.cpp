// The two estimators of the position-free walk compute the same BSDF: the
// bidirectional estimator's mean equals the unidirectional one's within
// noise (isotropic and anisotropic, both height models, mirror and gold
// facets, orders >= 2 where they differ, order 1 being analytic in both;
// Lambertian facets, every order; dielectric facets, both sides).
#include "common/material/position_free_walk.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace skyfarm::material {
namespace {

glm::dvec3 direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

struct Case {
  double alpha_x;
  double alpha_y;
  HeightCorrelation correlation;
  ConductorFresnel fresnel;
  glm::dvec3 wi;
  glm::dvec3 wo;
};

TEST(PositionFreeWalk, BidirectionalAndUnidirectionalEstimatorsAgree) {
  const ConductorFresnel gold{{0.43, 2.46}, false};
  const Case cases[] = {
      {0.1, 0.1, HeightCorrelation::correlated, ConductorFresnel::mirror(), direction(0.7, 0.0), direction(0.7, 0.0)},
      {0.1, 0.1, HeightCorrelation::correlated, ConductorFresnel::mirror(), direction(0.7, 0.0), direction(0.5, 3.0)},
      {0.5, 0.5, HeightCorrelation::uncorrelated, gold, direction(1.2, 0.0), direction(0.3, 1.0)},
      {1.0, 0.2, HeightCorrelation::correlated, ConductorFresnel::mirror(), direction(0.4, 0.0), direction(1.3, 2.0)},
      {2.0, 2.0, HeightCorrelation::correlated, ConductorFresnel::mirror(), direction(1.0, 0.0), direction(0.2, 0.5)},
  };
  for (const Case& c : cases) {
    const MicrofacetDistribution dist(MicrofacetModel::ggx, c.alpha_x, c.alpha_y);
    const PositionFreeWalk walk(dist, Facet::conductor(c.fresnel), c.correlation);
    RandomSequence rng(31);
    constexpr int kSamples = 100000;
    double s[2] = {0.0, 0.0};
    double s2[2] = {0.0, 0.0};
    for (int i = 0; i < kSamples; ++i) {
      const double uni = walk.estimate(c.wi, c.wo, rng, 2);
      // Order 1 has one strategy in both (the analytic single bounce).
      const double bi = walk.estimate_bidirectional(c.wi, c.wo, rng) - walk.estimate(c.wi, c.wo, rng, 1, 1);
      s[0] += uni;
      s2[0] += uni * uni;
      s[1] += bi;
      s2[1] += bi * bi;
    }
    const double m0 = s[0] / kSamples;
    const double m1 = s[1] / kSamples;
    const double v0 = (s2[0] / kSamples - m0 * m0) / kSamples;
    const double v1 = (s2[1] / kSamples - m1 * m1) / kSamples;
    std::printf("alpha %.1f x %.1f: orders >= 2 unidirectional %.6f +- %.6f, bidirectional %.6f +- %.6f\n",
                c.alpha_x, c.alpha_y, m0, std::sqrt(v0), m1, std::sqrt(v1));
    EXPECT_GT(m0, 0.0);
    EXPECT_NEAR(m0, m1, 4.5 * std::sqrt(v0 + v1));
  }
}

// The one-way and two-way estimates of f(wo, wi) |wo.z|, 40 000 each from
// one sequence: their means and the variances of the means.
struct BothEstimates {
  double one_way, one_way_variance, two_way, two_way_variance;
};
BothEstimates both_estimators(const PositionFreeWalk& walk, const glm::dvec3& wi, const glm::dvec3& wo,
                              std::uint64_t seed) {
  RandomSequence rng(seed);
  constexpr int kSamples = 40000;
  double s[2] = {0.0, 0.0};
  double s2[2] = {0.0, 0.0};
  for (int i = 0; i < kSamples; ++i) {
    const double uni = walk.estimate(wi, wo, rng);
    const double bi = walk.estimate_bidirectional(wi, wo, rng);
    s[0] += uni;
    s2[0] += uni * uni;
    s[1] += bi;
    s2[1] += bi * bi;
  }
  const double m0 = s[0] / kSamples;
  const double m1 = s[1] / kSamples;
  return {m0, (s2[0] / kSamples - m0 * m0) / kSamples, m1, (s2[1] / kSamples - m1 * m1) / kSamples};
}

// Lambertian facets: the whole estimate (order 1 included: both estimators
// connect a visible normal to wo there) at alpha 0.1 to 2, both height
// models, an anisotropic surface, Beckmann, and grazing light or view.  The
// two-way estimator must not be noisier than the one-way one (checked with
// a wide margin: where it gains least, it is about as noisy).
TEST(PositionFreeWalk, DiffuseBidirectionalAndUnidirectionalEstimatorsAgree) {
  struct DiffuseCase {
    MicrofacetModel model;
    double alpha_x;
    double alpha_y;
    HeightCorrelation correlation;
    double albedo;
    glm::dvec3 wi;
    glm::dvec3 wo;
  };
  constexpr MicrofacetModel kGgx = MicrofacetModel::ggx;
  constexpr MicrofacetModel kBeckmann = MicrofacetModel::beckmann;
  constexpr HeightCorrelation kCorrelated = HeightCorrelation::correlated;
  constexpr HeightCorrelation kUncorrelated = HeightCorrelation::uncorrelated;
  const DiffuseCase cases[] = {
      {kGgx, 0.1, 0.1, kCorrelated, 1.0, direction(0.7, 0.0), direction(0.5, 3.0)},
      {kGgx, 0.1, 0.1, kUncorrelated, 0.8, direction(1.45, 0.0), direction(0.2, 1.0)},
      {kGgx, 0.5, 0.5, kCorrelated, 0.8, direction(0.3, 0.0), direction(1.2, 2.0)},
      {kGgx, 0.5, 0.5, kUncorrelated, 1.0, direction(1.0, 0.0), direction(1.0, 0.0)},
      {kGgx, 1.0, 1.0, kCorrelated, 1.0, direction(1.5, 0.0), direction(0.4, 0.5)},
      {kGgx, 1.0, 0.2, kCorrelated, 0.9, direction(0.6, 0.0), direction(1.4, 1.5)},
      {kGgx, 2.0, 2.0, kCorrelated, 1.0, direction(1.0, 0.0), direction(0.2, 0.5)},
      {kGgx, 2.0, 2.0, kUncorrelated, 0.9, direction(0.0, 0.0), direction(1.5, 3.1)},
      {kBeckmann, 0.7, 0.7, kCorrelated, 1.0, direction(1.2, 0.0), direction(1.3, 2.5)},
  };
  for (const DiffuseCase& c : cases) {
    const MicrofacetDistribution dist(c.model, c.alpha_x, c.alpha_y);
    const PositionFreeWalk walk(dist, Facet::diffuse(c.albedo), c.correlation);
    const auto [m0, v0, m1, v1] = both_estimators(walk, c.wi, c.wo, 47);
    std::printf("diffuse alpha %.1f x %.1f: unidirectional %.6f +- %.6f, bidirectional %.6f +- %.6f\n", c.alpha_x,
                c.alpha_y, m0, std::sqrt(v0), m1, std::sqrt(v1));
    EXPECT_GT(m0, 0.0);
    EXPECT_NEAR(m0, m1, 4.0 * std::sqrt(v0 + v1));
    EXPECT_LT(v1, 1.5 * v0);
  }
}

// Dielectric facets: reflection and transmission from both sides (the walk
// crosses the interface in the mirrored frame, and the reverse walk's
// refraction term carries eta^2), alpha 0.1 to 2, Beckmann, grazing
// included.  Order 1 is analytic in both estimators.  Not noisier than the
// one-way estimator, as for Lambertian facets.
TEST(PositionFreeWalk, DielectricBidirectionalAndUnidirectionalEstimatorsAgree) {
  struct DielectricCase {
    MicrofacetModel model;
    double alpha;
    HeightCorrelation correlation;
    double eta;
    glm::dvec3 wi;
    glm::dvec3 wo;
  };
  auto below = [](glm::dvec3 w) { return glm::dvec3(w.x, w.y, -w.z); };
  constexpr MicrofacetModel kGgx = MicrofacetModel::ggx;
  constexpr MicrofacetModel kBeckmann = MicrofacetModel::beckmann;
  constexpr HeightCorrelation kCorrelated = HeightCorrelation::correlated;
  constexpr HeightCorrelation kUncorrelated = HeightCorrelation::uncorrelated;
  const DielectricCase cases[] = {
      {kGgx, 0.1, kCorrelated, 1.5, direction(0.7, 0.0), below(direction(0.5, 3.0))},
      {kGgx, 0.5, kCorrelated, 1.33, direction(0.3, 0.0), direction(1.2, 2.0)},
      {kGgx, 0.5, kUncorrelated, 1.5, direction(1.0, 0.0), below(direction(1.0, 0.0))},
      {kGgx, 1.0, kCorrelated, 1.5, below(direction(1.5, 0.0)), below(direction(0.4, 0.5))},
      {kGgx, 1.0, kCorrelated, 1.5, below(direction(0.6, 0.0)), direction(0.3, 1.5)},
      {kGgx, 2.0, kCorrelated, 1.33, direction(1.4, 0.0), below(direction(0.2, 0.5))},
      {kGgx, 2.0, kUncorrelated, 1.5, below(direction(0.2, 0.0)), below(direction(1.5, 3.1))},
      {kGgx, 0.1, kCorrelated, 1.5, direction(1.5, 0.0), direction(0.9, 3.0)},
      {kBeckmann, 0.7, kCorrelated, 1.5, below(direction(0.9, 0.0)), direction(0.5, 1.0)},
  };
  for (const DielectricCase& c : cases) {
    const MicrofacetDistribution dist(c.model, c.alpha, c.alpha);
    const PositionFreeWalk walk(dist, Facet::dielectric(c.eta), c.correlation);
    const auto [m0, v0, m1, v1] = both_estimators(walk, c.wi, c.wo, 53);
    std::printf("dielectric alpha %.1f %s: unidirectional %.6f +- %.6f, bidirectional %.6f +- %.6f\n", c.alpha,
                (c.wo.z > 0.0) == (c.wi.z > 0.0) ? "R" : "T", m0, std::sqrt(v0), m1, std::sqrt(v1));
    EXPECT_GT(m0, 0.0);
    EXPECT_NEAR(m0, m1, 4.0 * std::sqrt(v0 + v1));
    EXPECT_LT(v1, 1.5 * v0);
  }
}

// A walk capped at two bounces gives the same truncated BSDF by both
// estimators (the two-way one joins only paths of at most two bounces, so
// that each has all its strategies): Lambertian reflection, dielectric
// transmission.
TEST(PositionFreeWalk, BothEstimatorsStopAtTheSameOrder) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 1.0, 1.0);
  for (const Facet& facet : {Facet::diffuse(1.0), Facet::dielectric(1.5)}) {
    const PositionFreeWalk capped(dist, facet, HeightCorrelation::correlated, 2);
    const PositionFreeWalk full(dist, facet, HeightCorrelation::correlated);
    const glm::dvec3 wi = direction(1.2, 0.0);
    glm::dvec3 wo = direction(0.8, 2.0);
    if (facet.kind == FacetKind::dielectric) wo.z = -wo.z;
    RandomSequence rng(61);
    constexpr int kSamples = 40000;
    double s[3] = {0.0, 0.0, 0.0};
    double s2[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < kSamples; ++i) {
      const double x[3] = {capped.estimate(wi, wo, rng), capped.estimate_bidirectional(wi, wo, rng),
                           full.estimate_bidirectional(wi, wo, rng)};
      for (int k = 0; k < 3; ++k) {
        s[k] += x[k];
        s2[k] += x[k] * x[k];
      }
    }
    double m[3];
    double v[3];
    for (int k = 0; k < 3; ++k) {
      m[k] = s[k] / kSamples;
      v[k] = (s2[k] / kSamples - m[k] * m[k]) / kSamples;
    }
    std::printf("%s, at most 2 bounces: one-way %.6f +- %.6f, two-way %.6f +- %.6f; uncapped two-way %.6f\n",
                facet.kind == FacetKind::diffuse ? "diffuse" : "dielectric", m[0], std::sqrt(v[0]), m[1],
                std::sqrt(v[1]), m[2]);
    EXPECT_NEAR(m[0], m[1], 4.0 * std::sqrt(v[0] + v[1]));
    // The cap matters here: the orders above 2 are well outside the noise.
    EXPECT_GT(m[2] - m[1], 6.0 * std::sqrt(v[1] + v[2]));
  }
}

}  // namespace
}  // namespace skyfarm::material

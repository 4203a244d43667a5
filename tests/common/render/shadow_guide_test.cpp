// The shadow guide (common/render/shadow_guide.h): where it applies, that its
// pdf is a density over the sphere (integral 1), and that its samples follow
// that pdf (chi-square, tests/support/chi2.h), at vertices low, high and far
// towards the sun in a twilight sky.
#include "common/render/shadow_guide.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/render/scene.h"
#include "tests/support/chi2.h"
#include "tests/support/sun_specs.h"

namespace skyfarm {
namespace {

Scene twilight_scene() {
  return Scene::from_specs(AtmosphereSpec{}, testing::sun_spec(96.0, 0.0, 0.2666), Location{}, std::nullopt, 400.0,
                           700.0);
}

// A point at altitude h_m, `towards_sun_deg` of arc from the observer towards
// the sun (its sun zenith angle that much smaller), planet-centred.
glm::dvec3 point(const Scene& scene, double h_m, double towards_sun_deg) {
  const glm::dvec3 up = glm::normalize(scene.observer());
  const glm::dvec3 s = scene.sun().direction();
  const glm::dvec3 t = glm::normalize(s - glm::dot(s, up) * up);
  const double a = towards_sun_deg * kDegToRad;
  return (scene.atmosphere().planet_radius_m() + h_m) * (std::cos(a) * up + std::sin(a) * t);
}

// The frame at p: z up, x the sun's azimuth on the local horizontal.
struct LocalFrame {
  glm::dvec3 x, y, z;
  explicit LocalFrame(const glm::dvec3& p, const glm::dvec3& s) {
    z = glm::normalize(p);
    x = glm::normalize(s - glm::dot(s, z) * z);
    y = glm::cross(z, x);
  }
  glm::dvec3 to_world(const glm::dvec3& v) const { return v.x * x + v.y * y + v.z * z; }
  glm::dvec3 to_local(const glm::dvec3& w) const { return {glm::dot(w, x), glm::dot(w, y), glm::dot(w, z)}; }
};

struct Vertex {
  const char* name;
  double h_m, towards_sun_deg;
};
const Vertex kVertices[] = {{"1 km over the observer", 1000.0, 0.0},
                            {"15 km, 2 deg towards the sun", 15000.0, 2.0},
                            {"40 km, 4 deg towards the sun", 40000.0, 4.0}};

TEST(ShadowGuide, CoversOnlyWhereTheSunIsBelowTheLocalHorizontal) {
  const Scene scene = twilight_scene();
  const ShadowGuide guide(scene);
  for (const Vertex& v : kVertices) EXPECT_TRUE(guide.covers(point(scene, v.h_m, v.towards_sun_deg))) << v.name;
  // 8 deg of arc towards the sun it has risen 2 deg above the horizontal there.
  EXPECT_FALSE(guide.covers(point(scene, 5000.0, 8.0)));
}

// The pdf integrated over the sphere by the midpoint rule in (mu, phi) on a
// grid much finer than the guide's cells (the cells' edges cross the grid's
// cells, so the sum is off by about the jumps at the edges times 1/N).
TEST(ShadowGuide, PdfIntegratesToOneOverTheSphere) {
  const Scene scene = twilight_scene();
  const ShadowGuide guide(scene);
  const int n_mu = 1600, n_phi = 800;
  for (const Vertex& v : kVertices) {
    const glm::dvec3 p = point(scene, v.h_m, v.towards_sun_deg);
    const LocalFrame f(p, scene.sun().direction());
    double sum = 0.0;
    for (int i = 0; i < n_mu; ++i) {
      const double mu = -1.0 + 2.0 * (i + 0.5) / n_mu, sin_theta = std::sqrt(1.0 - mu * mu);
      for (int k = 0; k < n_phi; ++k) {
        const double phi = 2.0 * kPi * (k + 0.5) / n_phi;
        sum += guide.pdf(p, f.to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu}));
      }
    }
    EXPECT_NEAR(sum * (2.0 / n_mu) * (2.0 * kPi / n_phi), 1.0, 5e-3) << v.name;
  }
}

// Samples binned in the local frame (16 x 16 bins in the cosine of the zenith
// angle and the azimuth from the sun's) against the pdf's integral over each
// bin by the midpoint rule on a 50 x 50 grid per bin (adaptive quadrature
// of a pdf with this many edges is too slow for a unit test); Pearson's
// statistic (tests/support/chi2.h).  No sample falls where the pdf is 0.
TEST(ShadowGuide, SamplesFollowThePdf) {
  const Scene scene = twilight_scene();
  const ShadowGuide guide(scene);
  std::mt19937_64 rng(17);
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  constexpr int kBins = 16, kFine = 50, kSamples = 200000;
  for (const Vertex& v : kVertices) {
    const glm::dvec3 p = point(scene, v.h_m, v.towards_sun_deg);
    const LocalFrame f(p, scene.sun().direction());
    std::vector<double> observed(kBins * kBins, 0.0), expected(kBins * kBins, 0.0);
    for (int i = 0; i < kSamples; ++i) {
      const double u1 = uniform(), u2 = uniform(), u3 = uniform();
      const glm::dvec3 wi = guide.sample(p, u1, u2, u3);
      ASSERT_NEAR(glm::length(wi), 1.0, 1e-12) << v.name;
      ASSERT_GT(guide.pdf(p, wi), 0.0) << v.name << ": a sample where the pdf is 0";
      const glm::dvec3 w = f.to_local(wi);
      const double phi = std::atan2(w.y, w.x) + kPi;  // [0, 2 pi]
      const int a = std::clamp(static_cast<int>((w.z + 1.0) * 0.5 * kBins), 0, kBins - 1);
      const int b = std::clamp(static_cast<int>(phi / (2.0 * kPi) * kBins), 0, kBins - 1);
      observed[static_cast<std::size_t>(a * kBins + b)] += 1.0;
    }
    const double d_mu = 2.0 / (kBins * kFine), d_phi = 2.0 * kPi / (kBins * kFine);
    for (int i = 0; i < kBins * kFine; ++i) {
      const double mu = -1.0 + (i + 0.5) * d_mu, sin_theta = std::sqrt(1.0 - mu * mu);
      for (int k = 0; k < kBins * kFine; ++k) {
        const double phi = (k + 0.5) * d_phi - kPi;
        const double pdf = guide.pdf(p, f.to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu}));
        expected[static_cast<std::size_t>((i / kFine) * kBins + k / kFine)] += kSamples * pdf * d_mu * d_phi;
      }
    }
    double statistic = 0.0;
    int cells = 0;
    double pooled_o = 0.0, pooled_e = 0.0;  // bins expecting fewer than 5, pooled
    for (std::size_t c = 0; c < expected.size(); ++c) {
      if (expected[c] < 5.0) {
        ASSERT_FALSE(expected[c] < 1e-6 && observed[c] > 0.0) << v.name << ": samples where the pdf is 0";
        pooled_o += observed[c];
        pooled_e += expected[c];
        continue;
      }
      statistic += (observed[c] - expected[c]) * (observed[c] - expected[c]) / expected[c];
      ++cells;
    }
    if (pooled_e >= 5.0) {
      statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
      ++cells;
    }
    const double p_value = testing::chi2_survival(statistic, cells - 1);
    std::printf("[chi2] shadow guide, %-30s p=%.3g (dof %d)\n", v.name, p_value, cells - 1);
    EXPECT_GT(p_value, testing::sidak_significance(0.01, 3)) << v.name << ": statistic " << statistic;
  }
}

}  // namespace
}  // namespace skyfarm

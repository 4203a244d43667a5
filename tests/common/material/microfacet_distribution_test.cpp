// Oracles for the microfacet distributions: normalisation of D by
// quadrature, Smith's G1 against its defining projected-area integral, the
// visible-normal density against sampling (chi-square), and finiteness at the
// extremes of roughness and direction.
#include "common/material/microfacet_distribution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "tests/common/material/sphere_quadrature.h"

namespace skyfarm::material {
namespace {

using test::integrate_hemisphere;
using test::kPi;

struct Roughness {
  double alpha_x;
  double alpha_y;
};

const MicrofacetModel kModels[] = {MicrofacetModel::ggx, MicrofacetModel::beckmann};

std::string name(MicrofacetModel model) { return model == MicrofacetModel::ggx ? "ggx" : "beckmann"; }

std::vector<Roughness> normalisation_roughnesses() {
  std::vector<Roughness> r;
  for (double a : {0.05, 0.2, 0.5, 1.0, 2.0}) r.push_back({a, a});
  r.push_back({0.05, 0.5});
  r.push_back({1.0, 0.2});
  r.push_back({2.0, 0.05});
  return r;
}

glm::dvec3 direction(double theta_deg, double phi) {
  const double t = theta_deg * kPi / 180.0;
  return {std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t)};
}

// The projected area of the microsurface onto the macro plane is the macro
// area: integral D(wm) (wm . z) dwm = 1.
TEST(MicrofacetDistribution, NdfIsNormalised) {
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : normalisation_roughnesses()) {
      SCOPED_TRACE(name(model) + " alpha " + std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y));
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      const double integral = integrate_hemisphere([&](const glm::dvec3& wm) { return dist.D(wm) * wm.z; },
                                                   std::min(r.alpha_x, r.alpha_y), std::max(r.alpha_x, r.alpha_y),
                                                   {}, test::Region{}, 256);
      EXPECT_NEAR(integral, 1.0, 1e-6);
    }
  }
}

// Smith: the projected area of the normals facing w is cos(theta) (1 +
// Lambda(w)), i.e. G1(w) = cos(theta) / integral <w . wm>+ D(wm) dwm.
TEST(MicrofacetDistribution, G1MatchesProjectedAreaIntegral) {
  const Roughness roughnesses[] = {{0.2, 0.2}, {0.5, 0.5}, {1.0, 1.0}, {1.0, 0.1}};
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : roughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta : {0.0, 30.0, 60.0, 80.0, 88.0}) {
        for (double phi : {0.0, 0.7, 1.9}) {
          SCOPED_TRACE(name(model) + " alpha " + std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y) +
                       " theta " + std::to_string(theta) + " phi " + std::to_string(phi));
          const glm::dvec3 w = direction(theta, phi);
          const double area = integrate_hemisphere(
              [&](const glm::dvec3& wm) { return std::max(glm::dot(w, wm), 0.0) * dist.D(wm); },
              std::min(r.alpha_x, r.alpha_y), std::max(r.alpha_x, r.alpha_y), {w});
          const double g1_numeric = w.z / area;
          EXPECT_NEAR(dist.g1(w), g1_numeric, 2e-4 * g1_numeric);
          EXPECT_GE(dist.lambda(w), 0.0);
        }
      }
    }
  }
}

// D_wo is a probability density over the normals for wo on both sides of
// the macro surface.
TEST(MicrofacetDistribution, VisibleNormalPdfIntegratesToOne) {
  const Roughness roughnesses[] = {{0.3, 0.3}, {0.8, 0.2}, {1.5, 1.5}};
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : roughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta : {0.0, 45.0, 85.0, 100.0, 135.0}) {
        SCOPED_TRACE(name(model) + " alpha " + std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y) +
                     " theta " + std::to_string(theta));
        const glm::dvec3 wo = direction(theta, 0.4);
        const double integral =
            integrate_hemisphere([&](const glm::dvec3& wm) { return dist.visible_normal_pdf(wo, wm); },
                                 std::min(r.alpha_x, r.alpha_y), std::max(r.alpha_x, r.alpha_y), {wo});
        EXPECT_NEAR(integral, 1.0, 2e-4);
      }
    }
  }
}

// Uniform doubles in [0, 1) from a fixed-seed 64-bit Mersenne twister (the
// top 53 bits), the same on every platform.
class Uniform {
 public:
  explicit Uniform(std::uint64_t seed) : engine_(seed) {}
  double operator()() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 engine_;
};

// Upper quantile of the chi-square distribution with k degrees of freedom
// at the standard-normal quantile z (Wilson & Hilferty 1931).
double chi_square_quantile(double k, double z) {
  const double c = 2.0 / (9.0 * k);
  const double t = 1.0 - c + z * std::sqrt(c);
  return k * t * t * t;
}

// Sampled normals binned on the hemisphere (polar bins graded with the
// roughness, azimuth bins uniform) against the expected counts from the
// quadrature of D_wo over each bin; bins expected to hold fewer than 5
// samples are pooled.
TEST(MicrofacetDistribution, VisibleNormalSamplingMatchesPdfChiSquare) {
  const Roughness roughnesses[] = {{0.3, 0.3}, {0.8, 0.2}};
  constexpr int kThetaBins = 16;
  constexpr int kPhiBins = 32;
  constexpr int kSamples = 200000;
  std::uint64_t seed = 1;
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : roughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      const double alpha = std::sqrt(r.alpha_x * r.alpha_y);
      // Polar bin edges: tan(theta) = alpha s / (1 - s), s uniform in [0, 1].
      std::vector<double> edges(kThetaBins + 1);
      for (int i = 0; i <= kThetaBins; ++i) {
        const double s = static_cast<double>(i) / kThetaBins;
        edges[i] = i == kThetaBins ? kPi / 2.0 : std::atan(alpha * s / (1.0 - s));
      }
      for (double theta_o : {0.0, 40.0, 75.0, 89.0, 120.0, 160.0}) {
        SCOPED_TRACE(name(model) + " alpha " + std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y) +
                     " theta_o " + std::to_string(theta_o));
        const glm::dvec3 wo = direction(theta_o, 0.3);

        std::vector<double> expected(kThetaBins * kPhiBins, 0.0);
        for (int i = 0; i < kThetaBins; ++i) {
          for (int j = 0; j < kPhiBins; ++j) {
            test::Region bin;
            bin.theta0 = edges[i];
            bin.theta1 = edges[i + 1];
            bin.phi0 = 2.0 * kPi * j / kPhiBins;
            bin.phi1 = 2.0 * kPi * (j + 1) / kPhiBins;
            expected[i * kPhiBins + j] =
                kSamples * integrate_hemisphere([&](const glm::dvec3& wm) { return dist.visible_normal_pdf(wo, wm); },
                                                std::min(r.alpha_x, r.alpha_y), std::max(r.alpha_x, r.alpha_y), {wo},
                                                bin, 2, 12);
          }
        }

        std::vector<double> observed(expected.size(), 0.0);
        int invalid = 0;  // not unit, below the surface, or facing away from wo
        Uniform uniform(seed++);
        for (int n = 0; n < kSamples; ++n) {
          const glm::dvec2 u(uniform(), uniform());
          const glm::dvec3 wm = dist.sample_visible_normal(wo, u);
          if (!(std::abs(glm::length(wm) - 1.0) <= 1e-12 && wm.z >= 0.0 && glm::dot(wm, wo) > -1e-12)) ++invalid;
          const double theta = std::acos(std::min(wm.z, 1.0));
          double phi = std::atan2(wm.y, wm.x);
          if (phi < 0.0) phi += 2.0 * kPi;
          const int i = std::min<int>(std::upper_bound(edges.begin(), edges.end(), theta) - edges.begin() - 1,
                                      kThetaBins - 1);
          const int j = std::min<int>(static_cast<int>(phi / (2.0 * kPi) * kPhiBins), kPhiBins - 1);
          observed[i * kPhiBins + j] += 1.0;
        }

        EXPECT_EQ(invalid, 0);
        double chi2 = 0.0;
        int dof = -1;
        double pooled_expected = 0.0;
        double pooled_observed = 0.0;
        double total_expected = 0.0;
        for (std::size_t k = 0; k < expected.size(); ++k) {
          total_expected += expected[k];
          if (expected[k] < 5.0) {
            pooled_expected += expected[k];
            pooled_observed += observed[k];
            continue;
          }
          const double d = observed[k] - expected[k];
          chi2 += d * d / expected[k];
          ++dof;
        }
        if (pooled_expected >= 5.0) {
          const double d = pooled_observed - pooled_expected;
          chi2 += d * d / pooled_expected;
          ++dof;
        } else {
          EXPECT_LT(pooled_observed, 5.0 + 5.0 * std::sqrt(pooled_expected + 1.0));
        }
        EXPECT_NEAR(total_expected / kSamples, 1.0, 1e-3);
        // Deep below the surface a smooth Beckmann surface shows only its
        // steepest normals: they fill a few bins, which still test the shape.
        ASSERT_GE(dof, 3);
        // z = 4.75: a false alarm probability of about 1e-6 per case.
        EXPECT_LT(chi2, chi_square_quantile(dof, 4.75)) << "dof " << dof;
      }
    }
  }
}

TEST(MicrofacetDistribution, RejectsInvalidRoughness) {
  for (MicrofacetModel model : kModels) {
    EXPECT_THROW(MicrofacetDistribution(model, 0.0, 0.5), std::invalid_argument);
    EXPECT_THROW(MicrofacetDistribution(model, 0.5, -1.0), std::invalid_argument);
    EXPECT_THROW(MicrofacetDistribution(model, std::nan(""), 0.5), std::invalid_argument);
    EXPECT_NO_THROW(MicrofacetDistribution(model, 1e-4, 2.0));
  }
}

// Extreme roughness and grazing directions: everything finite and
// non-negative, G1 in [0, 1], sampled normals unit and above the surface.
TEST(MicrofacetDistribution, StableAtExtremeRoughnessAndGrazing) {
  const Roughness roughnesses[] = {{1e-4, 1e-4}, {2.0, 2.0}, {1e-4, 2.0}};
  std::vector<glm::dvec3> directions = {{0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}, {0.6, 0.8, 0.0}};
  for (double z : {1e-300, 1e-12, 1e-6, 1e-3, 0.5, 1.0 - 1e-12}) {
    for (double phi : {0.0, 0.9, 2.4}) {
      const double s = std::sqrt(1.0 - z * z);
      directions.push_back({s * std::cos(phi), s * std::sin(phi), z});
      directions.push_back({s * std::cos(phi), s * std::sin(phi), -z});
    }
  }
  Uniform uniform(99);
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : roughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (const glm::dvec3& w : directions) {
        SCOPED_TRACE(name(model) + " alpha " + std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y) +
                     " w " + std::to_string(w.x) + "," + std::to_string(w.y) + "," + std::to_string(w.z));
        const double d = dist.D(w);
        EXPECT_TRUE(std::isfinite(d));
        EXPECT_GE(d, 0.0);
        const double lambda = dist.lambda(w);
        EXPECT_FALSE(std::isnan(lambda));  // +infinity at w.z == 0 is its value
        EXPECT_GE(lambda, 0.0);
        const double g1 = dist.g1(w);
        EXPECT_TRUE(std::isfinite(g1));
        EXPECT_GE(g1, 0.0);
        EXPECT_LE(g1, 1.0);
        if (w.z <= -0.5) continue;  // steeply below: near-mirror normals cannot face it
        for (int n = 0; n < 64; ++n) {
          const glm::dvec3 wm = dist.sample_visible_normal(w, glm::dvec2(uniform(), uniform()));
          ASSERT_TRUE(std::isfinite(wm.x) && std::isfinite(wm.y) && std::isfinite(wm.z));
          EXPECT_NEAR(glm::length(wm), 1.0, 1e-12);
          EXPECT_GE(wm.z, 0.0);
          const double pdf = dist.visible_normal_pdf(w, wm);
          EXPECT_TRUE(std::isfinite(pdf));
          EXPECT_GE(pdf, 0.0);
        }
      }
    }
  }
}

}  // namespace
}  // namespace skyfarm::material

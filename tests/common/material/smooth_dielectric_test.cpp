// SmoothDielectric against the closed forms of a smooth interface: the two
// lobes' probabilities sum to 1 (R + T = 1), the refracted direction obeys
// Snell's law and lies in the plane of incidence, the radiance factor is
// (n_wo / n_wi)^2, total internal reflection leaves no refraction, and a
// refraction retraced from the other side returns to wo.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "common/material/fresnel.h"
#include "common/material/smooth_dielectric.h"

namespace skyfarm::material {
namespace {

glm::dvec3 direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TEST(SmoothDielectric, LobesSumToOneObeySnellAndCarryTheRadianceFactor) {
  const double eta = 1.5;
  const SmoothDielectric radiance(eta);
  const SmoothDielectric importance(eta, TransportMode::importance);
  for (double theta_deg : {0.0, 20.0, 45.0, 70.0, 89.0}) {
    for (bool inside : {false, true}) {
      glm::dvec3 wo = direction(theta_deg * M_PI / 180.0, 0.7);
      if (inside) wo.z = -wo.z;
      const double n_o = inside ? eta : 1.0, n_i = inside ? 1.0 : eta;
      const auto r = radiance.lobe(wo, true);
      const auto t = radiance.lobe(wo, false);
      ASSERT_TRUE(r);
      const double F = fresnel_dielectric(std::abs(wo.z), n_i / n_o);
      EXPECT_NEAR(r->probability, F, 1e-15);
      EXPECT_NEAR(r->weight, F, 1e-15);
      EXPECT_NEAR(r->wi.z, wo.z, 1e-15);
      EXPECT_NEAR(r->wi.x, -wo.x, 1e-15);
      const double sin_o = std::sqrt(1.0 - wo.z * wo.z);
      if (n_o * sin_o >= n_i) {  // total internal reflection
        EXPECT_FALSE(t) << theta_deg;
        EXPECT_DOUBLE_EQ(F, 1.0);
        continue;
      }
      ASSERT_TRUE(t) << theta_deg << " inside " << inside;
      EXPECT_NEAR(r->probability + t->probability, 1.0, 1e-14) << theta_deg;
      // Snell: n_o sin(theta_o) = n_i sin(theta_i), wi on the other side,
      // in the plane of incidence (azimuth opposite to wo's).
      const double sin_i = std::sqrt(std::max(0.0, 1.0 - t->wi.z * t->wi.z));
      EXPECT_NEAR(n_o * sin_o, n_i * sin_i, 1e-12) << theta_deg;
      EXPECT_LT(t->wi.z * wo.z, 0.0);
      EXPECT_NEAR(glm::length(t->wi), 1.0, 1e-14);
      if (sin_o > 0.0) {
        EXPECT_NEAR(t->wi.x * wo.y - t->wi.y * wo.x, 0.0, 1e-14);
        EXPECT_LT(t->wi.x * wo.x + t->wi.y * wo.y, 0.0);
      }
      // Radiance: (1 - F) (n_o / n_i)^2; importance: 1 - F.
      const auto t_imp = importance.lobe(wo, false);
      ASSERT_TRUE(t_imp);
      EXPECT_NEAR(t_imp->weight, 1.0 - F, 1e-14);
      EXPECT_NEAR(t->weight, (1.0 - F) * (n_o / n_i) * (n_o / n_i), 1e-14);
      // Retraced: the refraction of -wi from the other side is wo, with the
      // same transmittance and the inverse radiance factor.
      const auto back = radiance.lobe(t->wi, false);
      ASSERT_TRUE(back);
      EXPECT_NEAR(glm::length(back->wi - wo), 0.0, 1e-12) << theta_deg;
      EXPECT_NEAR(back->probability, t->probability, 1e-12);
      EXPECT_NEAR(back->weight * t->weight, t->probability * t->probability, 1e-12);
    }
  }
}

// sample() picks reflection with probability F: its value is 1 for a
// reflection and the radiance factor for a refraction, its pdf the
// lobe's probability, both flagged specular.
TEST(SmoothDielectric, SamplePicksTheLobeByFresnel) {
  const SmoothDielectric glass(1.5);
  RandomSequence rng(1);
  const glm::dvec3 wo = direction(0.6, 1.0);
  const double F = fresnel_dielectric(wo.z, 1.5);
  const auto r = glass.sample(wo, 0.5 * F, {0.3, 0.3}, rng);
  const auto t = glass.sample(wo, 0.5 * (1.0 + F), {0.3, 0.3}, rng);
  ASSERT_TRUE(r && t);
  EXPECT_TRUE(r->flags & kBsdfReflection);
  EXPECT_TRUE(r->flags & kBsdfSpecular);
  EXPECT_TRUE(t->flags & kBsdfTransmission);
  EXPECT_DOUBLE_EQ(r->value, 1.0);
  EXPECT_NEAR(r->pdf, F, 1e-15);
  EXPECT_NEAR(t->pdf, 1.0 - F, 1e-15);
  EXPECT_NEAR(t->value, 1.0 / 2.25, 1e-14);
  EXPECT_EQ(glass.f(wo, t->wi, rng), 0.0);
  EXPECT_EQ(glass.pdf(wo, t->wi), 0.0);
  EXPECT_THROW(SmoothDielectric(1.0), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm::material

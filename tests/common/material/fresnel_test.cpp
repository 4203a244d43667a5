// Oracles for the Fresnel reflectances: the closed forms at normal
// incidence, Brewster's angle, total internal reflection, energy
// conservation with the transmitted amplitudes, reciprocity across the
// interface, the conductor's dielectric and perfect-mirror limits.
#include "common/material/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>

namespace skyfarm::material {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Fresnel, DielectricNormalIncidence) {
  for (double n : {1.0001, 1.333, 1.5, 2.42, 0.75}) {
    SCOPED_TRACE("n " + std::to_string(n));
    const double expected = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
    EXPECT_NEAR(fresnel_dielectric(1.0, n), expected, 1e-15);
    // From the inside the relative index inverts; the normal-incidence
    // reflectance is the same.
    EXPECT_NEAR(fresnel_dielectric(-1.0, n), expected, 1e-15);
    const PolarizedReflectance r = fresnel_dielectric_polarized(1.0, n);
    EXPECT_NEAR(r.s, r.p, 1e-15);
  }
}

// At Brewster's angle tan(theta_B) = eta the p component vanishes, so the
// unpolarised reflectance is half the s component.
TEST(Fresnel, DielectricBrewsterAngle) {
  for (double n : {1.333, 1.5, 2.42}) {
    SCOPED_TRACE("n " + std::to_string(n));
    const PolarizedReflectance outside = fresnel_dielectric_polarized(std::cos(std::atan(n)), n);
    EXPECT_NEAR(outside.p, 0.0, 1e-15);
    EXPECT_GT(outside.s, 0.01);
    EXPECT_NEAR(fresnel_dielectric(std::cos(std::atan(n)), n), 0.5 * outside.s, 1e-15);
    const PolarizedReflectance inside = fresnel_dielectric_polarized(-std::cos(std::atan(1.0 / n)), n);
    EXPECT_NEAR(inside.p, 0.0, 1e-15);
    // Off Brewster's angle p reflects.
    EXPECT_GT(fresnel_dielectric_polarized(std::cos(std::atan(n) + 0.2), n).p, 1e-4);
  }
}

TEST(Fresnel, TotalInternalReflection) {
  for (double n : {1.333, 1.5}) {
    SCOPED_TRACE("n " + std::to_string(n));
    const double critical = std::asin(1.0 / n);
    for (double theta : {critical + 1e-9, critical + 0.1, kPi / 2.0 - 1e-6, kPi / 2.0}) {
      const PolarizedReflectance r = fresnel_dielectric_polarized(-std::cos(theta), n);
      EXPECT_EQ(r.s, 1.0);
      EXPECT_EQ(r.p, 1.0);
    }
    EXPECT_LT(fresnel_dielectric(-std::cos(critical - 0.05), n), 1.0);
    // A relative index below 1 seen from the outside is the same interface.
    EXPECT_EQ(fresnel_dielectric(std::cos(critical + 0.1), 1.0 / n), 1.0);
  }
}

// R + T = 1 per polarisation, with T from the transmitted amplitudes
// t_s = 2 cos_i / (cos_i + eta cos_t), t_p = 2 cos_i / (eta cos_i + cos_t)
// and the beam-area factor eta cos_t / cos_i.
TEST(Fresnel, DielectricConservesEnergy) {
  for (double n : {1.333, 1.5, 2.42}) {
    for (double theta = 0.0; theta < kPi / 2.0; theta += 0.05) {
      SCOPED_TRACE("n " + std::to_string(n) + " theta " + std::to_string(theta));
      const double cos_i = std::cos(theta);
      const double sin_t = std::sin(theta) / n;
      const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
      const double t_s = 2.0 * cos_i / (cos_i + n * cos_t);
      const double t_p = 2.0 * cos_i / (n * cos_i + cos_t);
      const double factor = n * cos_t / cos_i;
      const PolarizedReflectance r = fresnel_dielectric_polarized(cos_i, n);
      EXPECT_NEAR(r.s + factor * t_s * t_s, 1.0, 1e-13);
      EXPECT_NEAR(r.p + factor * t_p * t_p, 1.0, 1e-13);
      // Reciprocity: the same pair of angles seen from the other side.
      EXPECT_NEAR(fresnel_dielectric(-cos_t, n), fresnel_dielectric(cos_i, n), 1e-12);
    }
  }
}

TEST(Fresnel, ConductorWithoutAbsorptionEqualsDielectric) {
  for (double n : {1.333, 1.5, 0.7}) {
    for (double cos_i = 0.0; cos_i <= 1.0; cos_i += 0.01) {
      SCOPED_TRACE("n " + std::to_string(n) + " cos " + std::to_string(cos_i));
      const PolarizedReflectance c = fresnel_conductor_polarized(cos_i, {n, 0.0});
      const PolarizedReflectance d = fresnel_dielectric_polarized(cos_i, n);
      EXPECT_NEAR(c.s, d.s, 1e-12);
      EXPECT_NEAR(c.p, d.p, 1e-12);
    }
  }
}

// Normal incidence on a metal: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
TEST(Fresnel, ConductorNormalIncidence) {
  const std::complex<double> metals[] = {{0.43, 2.46}, {1.2, 7.0}, {0.06, 3.6}, {2.9, 3.0}};
  for (const std::complex<double>& eta : metals) {
    const double n = eta.real(), k = eta.imag();
    const double expected = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
    EXPECT_NEAR(fresnel_conductor(1.0, eta), expected, 1e-14);
  }
}

TEST(Fresnel, ConductorVeryLargeKReflectsAll) {
  for (double cos_i : {1.0, 0.7, 0.2, 1e-3, 0.0}) {
    SCOPED_TRACE("cos " + std::to_string(cos_i));
    EXPECT_GT(fresnel_conductor(cos_i, {1.0, 1e6}), 1.0 - 1e-5);
    EXPECT_LE(fresnel_conductor(cos_i, {1.0, 1e6}), 1.0);
  }
}

TEST(Fresnel, FiniteAndInUnitInterval) {
  for (double cos_i = -1.0; cos_i <= 1.0 + 1e-12; cos_i += 0.0025) {
    for (double eta : {1e-3, 0.5, 0.999, 1.0, 1.001, 1.5, 4.0, 1e3}) {
      const PolarizedReflectance r = fresnel_dielectric_polarized(cos_i, eta);
      for (double v : {r.s, r.p, r.average()}) {
        ASSERT_TRUE(std::isfinite(v)) << cos_i << " " << eta;
        ASSERT_GE(v, 0.0);
        ASSERT_LE(v, 1.0);
      }
    }
    for (std::complex<double> eta : {std::complex<double>(1.0, 0.0), {0.2, 3.0}, {1.5, 1e-9}, {0.5, 1e4}, {3.0, 0.5}}) {
      const PolarizedReflectance r = fresnel_conductor_polarized(cos_i, eta);
      for (double v : {r.s, r.p, r.average()}) {
        ASSERT_TRUE(std::isfinite(v)) << cos_i << " " << eta;
        ASSERT_GE(v, 0.0);
        ASSERT_LE(v, 1.0);
      }
    }
  }
}

}  // namespace
}  // namespace skyfarm::material

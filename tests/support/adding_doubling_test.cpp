// The adding-doubling slab solver (tests/support/adding_doubling.h) against
// published plane-parallel results, Chandrasekhar's semi-infinite solution,
// single scattering and energy conservation: it must be right before it
// judges the path tracer.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/clouds/cloud_optics.h"
#include "common/core/constants.h"
#include "tests/support/adding_doubling.h"

namespace skyfarm::testing {
namespace {

// --- Published results: the DISORT test problems (Stamnes, Tsay, Wiscombe &
// Jayaweera 1988, Appl. Opt. 27, 2502; the "correct answers" of its test
// driver disotest, 16 streams), which reproduce van de Hulst (1980, Multiple
// Light Scattering, Table 12: isotropic; Table 37: HG g = 0.75) and
// Sweigart (1970, ApJS 22, 1: Rayleigh).  Fluxes divided here by mu0 F0.
// With the same 16 double-Gauss streams the discrete problem is the same, so
// the agreement is the printed precision (5 digits); the converged 48-stream
// answers differ from them by < 1e-3 (the 16-stream quadrature error).
struct Published {
  const char* name;
  PhaseFunction phase;
  double tau, omega, mu0;
  double reflectance, total_transmittance;
};

std::vector<Published> published_cases() {
  const double direct_1 = std::exp(-0.03125 / 0.1);
  return {
      {"1a isotropic", PhaseFunction::isotropic(), 0.03125, 0.2, 0.1, 7.9945e-2 / kPi, 7.9411e-2 / kPi + direct_1},
      {"1b isotropic", PhaseFunction::isotropic(), 0.03125, 1.0, 0.1, 0.42292 / kPi, 0.42023 / kPi + direct_1},
      {"2c rayleigh", PhaseFunction::rayleigh(0.0), 5.0, 0.5, 0.080442, 6.24730e-2 / 0.252716, 2.51683e-4 / 0.252716},
      {"2d rayleigh", PhaseFunction::rayleigh(0.0), 5.0, 1.0, 0.080442, 0.225915 / 0.252716, 2.68008e-2 / 0.252716},
      {"3a hg 0.75", PhaseFunction::henyey_greenstein(0.75), 1.0, 1.0, 1.0, 0.247374 / kPi, 1.73849 / kPi + std::exp(-1.0)},
      {"3b hg 0.75", PhaseFunction::henyey_greenstein(0.75), 8.0, 1.0, 1.0, 1.59096 / kPi, 1.54958 / kPi + std::exp(-8.0)},
  };
}

TEST(AddingDoubling, MatchesPublishedDisortProblems) {
  for (const Published& c : published_cases()) {
    SCOPED_TRACE(c.name);
    const SlabFluxes s16 = adding_doubling_slab(c.tau, c.omega, c.phase, c.mu0, 16);
    // 5 printed digits: 1e-4 relative, plus the 16-stream delta-M of DISORT.
    EXPECT_NEAR(s16.reflectance / c.reflectance, 1.0, 1e-4);
    EXPECT_NEAR(s16.total_transmittance() / c.total_transmittance, 1.0, 1e-4);
    EXPECT_NEAR(s16.direct_transmittance, std::exp(-c.tau / c.mu0), 1e-15);
    const SlabFluxes s48 = adding_doubling_slab(c.tau, c.omega, c.phase, c.mu0, 48);
    EXPECT_NEAR(s48.reflectance / c.reflectance, 1.0, 1.5e-3);
    EXPECT_NEAR(s48.total_transmittance() / c.total_transmittance, 1.0, 1.5e-3);
  }
}

// --- Chandrasekhar (1950, Radiative Transfer, ch. IV-V): a semi-infinite
// isotropic medium reflects r(mu, mu0) = pi I / (mu0 E0) =
// omega H(mu) H(mu0) / (4 (mu + mu0)), with H the solution of
//   H(mu) = 1 + omega/2 mu H(mu) int_0^1 H(mu') / (mu + mu') dmu'
// (solved here by iteration on 200 Gauss points, Nystrom for other mu).
struct HFunction {
  double omega;
  std::vector<double> x, w, h;
  explicit HFunction(double omega_in) : omega(omega_in) {
    // H_{n+1}(mu) = 1 / (1 - omega/2 mu int H_n(mu') / (mu + mu') dmu'),
    // from H = 1: monotone convergence, fast for omega < 1 (slow at 1).
    gauss_legendre(200, 0.0, 1.0, x, w);
    h.assign(x.size(), 1.0);
    for (int it = 0; it < 5000; ++it) {
      std::vector<double> next(x.size());
      double change = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        next[i] = at(x[i]);
        change = std::max(change, std::abs(next[i] - h[i]));
      }
      h = next;
      if (change < 1e-14) break;
    }
  }
  double at(double mu) const {
    double s = 0.0;
    for (std::size_t j = 0; j < x.size(); ++j) s += w[j] * h[j] / (mu + x[j]);
    return 1.0 / (1.0 - 0.5 * omega * mu * s);
  }
};

TEST(AddingDoubling, SemiInfiniteIsotropicIsChandrasekhar) {
  for (const double omega : {0.9, 0.99}) {
    SCOPED_TRACE(::testing::Message() << "omega " << omega);
    const HFunction H(omega);
    // The H function itself: its zeroth moment is exactly
    // 2 (1 - sqrt(1 - omega)) / omega (from integrating the H equation).
    double alpha0 = 0.0;
    for (std::size_t i = 0; i < H.x.size(); ++i) alpha0 += H.w[i] * H.h[i];
    EXPECT_NEAR(alpha0, 2.0 * (1.0 - std::sqrt(1.0 - omega)) / omega, 1e-8);
    // Semi-infinite: the diffuse field decays as exp(-k tau), k ~ sqrt(3 (1 -
    // omega)), so tau = 400 leaves < 1e-20 for omega = 0.99.
    const double mu0 = 0.6;
    const SlabFluxes s = adding_doubling_slab(400.0, omega, PhaseFunction::isotropic(), mu0, 48);
    for (std::size_t i = 0; i < s.mu.size(); ++i) {
      const double expected = omega * H.at(s.mu[i]) * H.at(mu0) / (4.0 * (s.mu[i] + mu0));
      // 1e-5, but 1e-4 at the most grazing node (mu = 0.0024, where
      // 1/(mu + mu') is nearly singular for the 200-point H quadrature): 5e-5 seen.
      EXPECT_NEAR(s.reflection_function[i] / expected, 1.0, s.mu[i] < 0.01 ? 1e-4 : 1e-5) << "mu " << s.mu[i];
    }
    // Its plane albedo, 2 int r mu dmu = 1 - H(mu0) sqrt(1 - omega).
    EXPECT_NEAR(s.reflectance, 1.0 - H.at(mu0) * std::sqrt(1.0 - omega), 1e-5);
    EXPECT_LT(s.total_transmittance(), 1e-15);
  }
}

// --- Single scattering.  The multiple scattering is ~ omega tau ln(1/tau) of
// it (the grazing directions, where the slab is thick): 0.6 % at tau = 1e-3,
// 0.08 % at tau = 1e-4 (used).
// R = 2 pi omega int_0^1 pbar(-mu, mu0) mu/(mu + mu0) (1 - exp(-tau (1/mu + 1/mu0))) dmu,
// T = 2 pi omega int_0^1 pbar(mu, mu0) mu/(mu0 - mu) (exp(-tau/mu0) - exp(-tau/mu)) dmu,
// pbar the phase averaged over azimuth (here by 720-point midpoint sums).
TEST(AddingDoubling, ThinSlabIsSingleScattering) {
  const double tau = 1e-4, omega = 0.8, mu0 = 0.7;
  const PhaseFunction phase = PhaseFunction::henyey_greenstein(0.7);
  std::vector<double> x, w;
  gauss_legendre(400, 0.0, 1.0, x, w);
  auto pbar = [&](double mu_out, double mu_in) {  // directions' z cosines, signed
    const int n = 720;
    double s = 0.0;
    for (int k = 0; k < n; ++k) {
      const double phi = (k + 0.5) * 2.0 * kPi / n;
      s += phase.eval(mu_out * mu_in + std::sqrt((1 - mu_out * mu_out) * (1 - mu_in * mu_in)) * std::cos(phi));
    }
    return s / n;
  };
  double R = 0.0, T = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double mu = x[i];
    R += w[i] * pbar(mu, -mu0) * mu / (mu + mu0) * -std::expm1(-tau * (1.0 / mu + 1.0 / mu0));
    T += w[i] * pbar(-mu, -mu0) * mu / (mu0 - mu) * (std::exp(-tau / mu0) - std::exp(-tau / mu));
  }
  R *= 2.0 * kPi * omega;
  T *= 2.0 * kPi * omega;
  const SlabFluxes s = adding_doubling_slab(tau, omega, phase, mu0, 48);
  EXPECT_NEAR(s.reflectance / R, 1.0, 2e-3);  // measured 1 + 8.5e-4
  EXPECT_NEAR(s.diffuse_transmittance / T, 1.0, 2e-3);  // measured 1 + 1.6e-4
  EXPECT_NEAR(s.direct_transmittance, std::exp(-tau / mu0), 1e-15);
}

// --- Conservation: omega = 1 over a black ground, R + T = 1, and the
// delta-M Mie solution converged in the number of streams.
TEST(AddingDoubling, ConservativeSlabsConserveEnergy) {
  const PhaseFunction mie = cloud_optics(CloudParticle::kWater, 10.0).phase;
  for (const double tau : {1.0, 10.0, 100.0}) {
    for (const auto& [name, phase] : {std::pair{"isotropic", PhaseFunction::isotropic()},
                                      std::pair{"hg 0.85", PhaseFunction::henyey_greenstein(0.85)},
                                      std::pair{"mie 10 um", mie}}) {
      SCOPED_TRACE(::testing::Message() << name << " tau " << tau);
      const SlabFluxes s = adding_doubling_slab(tau, 1.0, phase, 0.5, 48);
      EXPECT_NEAR(s.reflectance + s.total_transmittance(), 1.0, 2e-5);
      EXPECT_GT(s.reflectance, 0.0);
      EXPECT_GT(s.diffuse_transmittance, 0.0);
    }
    const SlabFluxes m48 = adding_doubling_slab(tau, 1.0, mie, 0.5, 48);
    const SlabFluxes m96 = adding_doubling_slab(tau, 1.0, mie, 0.5, 96);
    EXPECT_NEAR(m48.reflectance, m96.reflectance, 1e-3) << "tau " << tau;
  }
}

TEST(AddingDoubling, RejectsBadParameters) {
  EXPECT_THROW(adding_doubling_slab(0.0, 1.0, PhaseFunction::isotropic(), 0.5), std::invalid_argument);
  EXPECT_THROW(adding_doubling_slab(1.0, 1.1, PhaseFunction::isotropic(), 0.5), std::invalid_argument);
  EXPECT_THROW(adding_doubling_slab(1.0, 1.0, PhaseFunction::isotropic(), 0.0), std::invalid_argument);
  EXPECT_THROW(adding_doubling_slab(1.0, 1.0, PhaseFunction::isotropic(), 0.5, 7), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm::testing

// The transmittance LUT against the atmosphere's reference quadrature
// (Atmosphere::optical_depth, adaptive Simpson to 1e-9 relative).
#include "common/lut/transmittance_lut.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {
namespace {

// Tolerance: 0.5 % of T, or 1e-4 absolute where T is tiny (brief of the LUT
// renderer).  Measured worst case over these rays: see the RecordProperty.
TEST(LutTransmittance, MatchesQuadratureOnRandomAndGrazingRays) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});  // air, ozone 300 DU, aerosols
  const SpectralGrid grid(360.0, 830.0, 6);
  const MediumTable medium = MediumTable::build(atm, grid);
  const TransmittanceLut lut = TransmittanceLut::build(medium);
  const double R = atm.planet_radius_m();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<double> T(6);
  double worst_rel = 0.0;
  for (int k = 0; k < 60; ++k) {
    const double h = k < 20 ? 100000.0 * U(rng) * U(rng) : 100000.0 * U(rng);
    const double r = R + h, mu_h = lut::horizon_mu(r, R);
    // A third of the rays within 0.5 deg above the horizon, a few exactly on it.
    double mu = mu_h + (1.0 - mu_h) * U(rng);
    if (k % 3 == 0) mu = std::cos(std::acos(mu_h) - 0.5 * 3.14159265358979 / 180.0 * U(rng));
    if (k % 10 == 0) mu = mu_h + 1e-12;
    lut.to_top(r, mu, T.data());
    const Ray ray{{0.0, 0.0, r}, {std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu}};
    for (int b = 0; b < grid.size(); ++b) {
      const double ref = std::exp(-atm.optical_depth(ray, 1e30, grid.centre_nm(b)));
      const double err = std::abs(T[static_cast<std::size_t>(b)] - ref);
      if (ref > 0.02) worst_rel = std::max(worst_rel, err / ref);
      EXPECT_LE(err, std::max(0.005 * ref, 1e-4))
          << "h " << h << " mu " << mu << " (horizon " << mu_h << ") " << grid.centre_nm(b) << " nm: ref " << ref;
    }
  }
  RecordProperty("worst_relative_error_T_gt_0.02", std::to_string(worst_rel));
}

// The table's own quadrature at its nodes (the tangent table for descending
// rays' second parts, fewer intervals on thin rows) against the plain rule
// on 2048 intervals per part, every 4th node of each axis: at most 0.8 of
// the tolerance max(0.5 % T, 1e-4) (measured on every node at 32 bins 0.70,
// the same as with 64 intervals on every part; docs/experiments/
// 2026-12-02-lut-build-time.md, "Below 20 ms").  The nodes sit at v = k / (n - 1), x_mu = 1 - (1 - v)^4
// (transmittance_lut.h).
TEST(LutTransmittance, NodesMatchAFineQuadrature) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const SpectralGrid grid(360.0, 830.0, 6);
  const MediumTable medium = MediumTable::build(atm, grid);
  const TransmittanceLut lut = TransmittanceLut::build(medium);
  std::vector<double> T(6), tau(6);
  double worst = 0.0;
  for (int j = 0; j < lut.r_samples(); j += 4)
    for (int i = 0; i < lut.mu_samples(); i += 4) {
      const double v = static_cast<double>(i) / (lut.mu_samples() - 1);
      double r, mu;
      lut.r_mu_from_unit(static_cast<double>(j) / (lut.r_samples() - 1), 1.0 - std::pow(1.0 - v, 4), &r, &mu);
      lut.to_top(r, mu, T.data());
      TransmittanceLut::optical_depth_to_top(medium, r, mu, 2048, tau.data());
      for (int b = 0; b < 6; ++b) {
        const double ref = std::exp(-tau[static_cast<std::size_t>(b)]);
        worst = std::max(worst, std::abs(T[static_cast<std::size_t>(b)] - ref) / std::max(0.005 * ref, 1e-4));
      }
    }
  EXPECT_LE(worst, 0.8);
  RecordProperty("worst_error_over_tolerance", std::to_string(worst));
}

// Rays into the ground see no sun; the parameterisation round-trips.
TEST(LutTransmittance, BlockedBelowTheHorizonAndMappingRoundTrips) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const SpectralGrid grid(400.0, 700.0, 2);
  const MediumTable medium = MediumTable::build(atm, grid, 128);
  const TransmittanceLut lut = TransmittanceLut::build(medium, 32, 16, 16);
  const double R = atm.planet_radius_m();
  std::vector<double> T(2);
  for (double h : {0.0, 1.0, 5000.0, 99999.0}) {
    lut.to_top(R + h, lut::horizon_mu(R + h, R) - 1e-9, T.data());
    EXPECT_EQ(T[0], 0.0);
    lut.to_top(R + h, 1.0, T.data());
    EXPECT_GT(T[0], 0.0);
    EXPECT_LE(T[0], 1.0);
  }
  for (double xr : {0.0, 0.3, 1.0})
    for (double xm : {0.0, 0.5, 0.999, 1.0}) {
      double r, mu, xr2, xm2;
      lut.r_mu_from_unit(xr, xm, &r, &mu);
      lut.unit_from_r_mu(r, mu, &xr2, &xm2);
      EXPECT_NEAR(xr2, xr, 1e-9);
      EXPECT_NEAR(xm2, xm, 1e-6);
    }
}

}  // namespace
}  // namespace skyfarm

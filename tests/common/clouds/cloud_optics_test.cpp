// The optics of cloud particles (common/clouds/cloud_optics.h) against the
// Mie tables they come from, geometric optics, and the Mie features a
// sampled phase function must keep (glory, fogbow).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/clouds/cloud_optics.h"
#include "common/core/constants.h"
#include "common/data/csv_table.h"
#include "tests/support/adding_doubling.h"

namespace skyfarm {
namespace {

// 2 pi int_{-1}^{1} f(mu) p(mu) dmu by 8-point Gauss-Legendre on 20000
// intervals, uniform in the scattering angle (0.009 deg wide: they resolve
// the forward peaks, whose widths are ~0.5 deg for the Mie table and ~1 deg
// for HG(0.98)).
template <class F>
double sphere_integral(const PhaseFunction& phase, F f) {
  std::vector<double> x, w;
  testing::gauss_legendre(8, 0.0, 1.0, x, w);
  const int n = 20000;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    const double hi = std::cos(k * kPi / n), lo = std::cos((k + 1) * kPi / n);
    for (int q = 0; q < 8; ++q) {
      const double mu = lo + (hi - lo) * x[q];
      sum += (hi - lo) * w[q] * f(mu) * phase.eval(mu);
    }
  }
  return 2.0 * kPi * sum;
}

// The histogram of scattering angles drawn from the phase by stratified
// u = (i + 1/2) / n (the inverse-CDF sampler is monotone, so the counts are
// the table's probabilities to +-1 sample), as a density per steradian in
// 1-degree bins: density[b] for angles [b, b+1) degrees.
std::vector<double> sampled_density_per_sr(const PhaseFunction& phase, int n) {
  std::vector<double> counts(180, 0.0);
  for (int i = 0; i < n; ++i) {
    const double mu = phase.sample_cos_theta((i + 0.5) / n);
    const double deg = std::acos(std::clamp(mu, -1.0, 1.0)) * kRadToDeg;
    counts[std::min(179, static_cast<int>(deg))] += 1.0;
  }
  std::vector<double> density(180);
  for (int b = 0; b < 180; ++b) {
    const double solid_angle = 2.0 * kPi * (std::cos(b * kDegToRad) - std::cos((b + 1) * kDegToRad));
    density[b] = counts[b] / n / solid_angle;
  }
  return density;
}

struct SummaryRow {
  double r_eff_um, extinction_per_km, albedo, g;
};
std::vector<SummaryRow> summary_rows() {
  const CsvTable csv = CsvTable::embedded("cloud_mie_water_summary.csv");
  std::vector<SummaryRow> rows;
  for (std::size_t i = 0; i < csv.rows(); ++i) {
    rows.push_back({csv.column("effective_radius_um")[i], csv.column("extinction_per_km_for_LWC_1g_m3")[i],
                    csv.column("single_scattering_albedo")[i], csv.column("asymmetry_parameter_g")[i]});
  }
  return rows;
}

TEST(CloudOptics, PhaseFunctionsAreNormalised) {
  for (const CloudParticle particle : {CloudParticle::kWater, CloudParticle::kIce}) {
    const CloudOptics optics = cloud_optics(particle, 10.0);
    // The tables' piecewise-linear interpolants are normalised exactly;
    // the quadrature resolves them to ~1e-6.
    EXPECT_NEAR(sphere_integral(optics.phase, [](double) { return 1.0; }), 1.0, 1e-4);
  }
}

// The libRadtran table gives g = 0.86429 at 10 um; the phase table's own
// <mu> (from 778 Legendre moments, 5 decimals) is 0.8643 (data README).
TEST(CloudOptics, WaterMeanCosineMatchesTheMieTable) {
  const CloudOptics optics = cloud_optics(CloudParticle::kWater, 10.0);
  EXPECT_NEAR(optics.phase.mean_cosine(), 0.86429, 1e-2);
  EXPECT_NEAR(sphere_integral(optics.phase, [](double mu) { return mu; }), 0.86429, 1e-2);
  EXPECT_DOUBLE_EQ(optics.asymmetry, 0.86429);
}

TEST(CloudOptics, WaterValuesAtTabulatedRadiiAreTheTable) {
  for (const SummaryRow& row : summary_rows()) {
    SCOPED_TRACE(::testing::Message() << "r_eff " << row.r_eff_um);
    const CloudOptics optics = cloud_optics(CloudParticle::kWater, row.r_eff_um);
    EXPECT_NEAR(optics.extinction_per_g_m3, row.extinction_per_km * 1e-3, 1e-12);
    EXPECT_NEAR(optics.albedo, row.albedo, 1e-12);
    EXPECT_NEAR(optics.asymmetry, row.g, 1e-12);
  }
  // Hand-checked values (the table's 10 and 10.5 um rows) and their midpoint.
  EXPECT_NEAR(cloud_optics(CloudParticle::kWater, 10.0).extinction_per_g_m3, 0.15665, 1e-12);
  EXPECT_NEAR(cloud_optics(CloudParticle::kWater, 10.25).extinction_per_g_m3, 0.5 * (0.15665 + 0.14898), 1e-12);
}

// Geometric optics: sigma_t = Q_ext * pi <r^2> N = (3/4) Q_ext LWC / (rho_w r_eff)
// with Q_ext -> 2 for size parameters >> 1 (van de Hulst 1957, sec. 8.22;
// Stephens 1978), i.e. 1.5 LWC / (rho_w r_eff).  At 550 nm and r >= 5 um
// (x >= 57) Mie's Q_ext is 2 within ~5 % (it approaches 2 from above).
TEST(CloudOptics, WaterExtinctionFollowsGeometricOpticsForLargeDroplets) {
  const double rho_w = 1000.0, lwc_kg_m3 = 1e-3;
  for (double r_um = 5.0; r_um <= 25.0; r_um += 2.5) {
    const double geometric = 1.5 * lwc_kg_m3 / (rho_w * r_um * 1e-6);
    const double sigma = cloud_optics(CloudParticle::kWater, r_um).extinction_per_g_m3;
    EXPECT_NEAR(sigma / geometric, 1.0, 0.10) << "r_eff " << r_um;
    EXPECT_GT(sigma / geometric, 1.0) << "Q_ext approaches 2 from above, r_eff " << r_um;
  }
}

// The glory (the backscatter rise to P(180) = 0.64 from 0.12 at 170 deg) and
// the fogbow (the primary rainbow of small droplets, P = 0.34 at 141.5 deg
// over 0.04 at 130 deg) must survive the tabulation and the sampler.
TEST(CloudOptics, SampledWaterPhaseHasGloryAndFogbow) {
  const PhaseFunction phase = cloud_optics(CloudParticle::kWater, 10.0).phase;
  const std::vector<double> p = sampled_density_per_sr(phase, 2000000);
  // Glory: the last degree well above the bin at 170 deg (x3 in the table).
  EXPECT_GT(p[179], 2.0 * p[170]);
  // Fogbow: the largest bin in 125-155 deg is a local maximum inside 130-145.
  const int peak = static_cast<int>(std::max_element(p.begin() + 125, p.begin() + 155) - p.begin());
  EXPECT_GE(peak, 130);
  EXPECT_LE(peak, 144);
  EXPECT_GT(p[peak], 3.0 * p[130]);
  EXPECT_GT(p[peak], 1.5 * p[154]);
  // And the densities are the table's (P / 4 pi) within a few per cent.
  EXPECT_NEAR(p[141] / (0.3358113 / (4.0 * kPi)), 1.0, 0.1);
}

// Ice: sigma_t = 3 IWC / (2 rho_ice r_eff), rho_ice = 917 kg m^-3 (exact).
TEST(CloudOptics, IceIsGeometricOptics) {
  for (const double r_um : {5.0, 30.0, 100.0}) {
    const CloudOptics optics = cloud_optics(CloudParticle::kIce, r_um);
    EXPECT_DOUBLE_EQ(optics.extinction_per_g_m3, 3.0 * 1e-3 / (2.0 * 917.0 * r_um * 1e-6));
    EXPECT_EQ(optics.albedo, 1.0);
  }
  // 30 um: 1 g m^-3 of ice is 0.0545 m^-1 (a 100 m thick cirrus of 0.02 g m^-3: tau 0.11).
  EXPECT_NEAR(cloud_optics(CloudParticle::kIce, 30.0).extinction_per_g_m3, 0.054526, 1e-6);
  // The two-term HG model's g is 0.5 * 0.98 + 0.5 * 0.52 = 0.75.
  const CloudOptics ice = cloud_optics(CloudParticle::kIce, 30.0);
  EXPECT_NEAR(ice.asymmetry, 0.75, 5e-3);
  EXPECT_NEAR(sphere_integral(ice.phase, [](double mu) { return mu; }), 0.75, 5e-3);
  // Its forward peak, HG(g; 0) = (1 + g) / (1 - g)^2 / (4 pi) for each term
  // (to the tabulation's renormalisation, ~1e-5).
  const double forward = 0.5 * (1.98 / (0.02 * 0.02) + 1.52 / (0.48 * 0.48)) / (4.0 * kPi);
  EXPECT_NEAR(ice.phase.eval(1.0) / forward, 1.0, 1e-4);
}

TEST(CloudOptics, PhaseTablesAreBuiltOnce) {
  const auto a = cloud_optics(CloudParticle::kWater, 5.0), b = cloud_optics(CloudParticle::kWater, 20.0);
  EXPECT_EQ(std::get<TabulatedPhase>(a.phase.model()).table, std::get<TabulatedPhase>(b.phase.model()).table);
  const auto c = cloud_optics(CloudParticle::kIce, 5.0), d = cloud_optics(CloudParticle::kIce, 50.0);
  EXPECT_EQ(std::get<TabulatedPhase>(c.phase.model()).table, std::get<TabulatedPhase>(d.phase.model()).table);
}

TEST(CloudOptics, RadiusOutOfRangeThrowsNamingIt) {
  for (const double r : {0.4, 25.5, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      cloud_optics(CloudParticle::kWater, r);
      ADD_FAILURE() << "no throw for " << r;
    } catch (const std::invalid_argument& e) {
      if (!std::isnan(r)) {
        std::ostringstream value;
        value << r;
        EXPECT_NE(std::string(e.what()).find(value.str()), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_NO_THROW(cloud_optics(CloudParticle::kWater, 0.5));
  EXPECT_NO_THROW(cloud_optics(CloudParticle::kWater, 25.0));
  EXPECT_THROW(cloud_optics(CloudParticle::kIce, 0.0), std::invalid_argument);
  EXPECT_THROW(cloud_optics(CloudParticle::kIce, -3.0), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm

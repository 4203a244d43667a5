// U.S. Standard Atmosphere 1976 against the standard's published values
// (NOAA-S/T 76-1562, Table I, geometric altitudes) and against the table of
// data/us_standard_atmosphere_1976.csv, which was computed independently from
// the standard's defining constants (data/README.md §4).
#include "common/atmosphere/us76.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/data/csv_table.h"

namespace skyfarm {
namespace {

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

TEST(Us76, SeaLevel) {
  // US76 Table I, Z = 0: rho = 1.2250 kg m^-3, n = 2.5470e25 m^-3, T = 288.15 K, P = 101325 Pa.
  EXPECT_NEAR(us76::mass_density_kg_per_m3(0.0), 1.2250, 5e-5);
  EXPECT_LT(rel(us76::number_density_per_m3(0.0), 2.5470e25), 1e-4);
  EXPECT_DOUBLE_EQ(us76::temperature_K(0.0), 288.15);
  EXPECT_DOUBLE_EQ(us76::pressure_Pa(0.0), 101325.0);
}

TEST(Us76, PublishedValuesAt11And20Km) {
  // US76 Table I, Z = 11 km: T = 216.774 K, P = 2.2699e4 Pa, rho = 3.6480e-1 kg m^-3.
  EXPECT_NEAR(us76::temperature_K(11000.0), 216.774, 1e-3);
  EXPECT_LT(rel(us76::pressure_Pa(11000.0), 2.2699e4), 1e-4);
  EXPECT_LT(rel(us76::mass_density_kg_per_m3(11000.0), 3.6480e-1), 1e-4);
  // Z = 20 km: T = 216.650 K, P = 5.5293e3 Pa, rho = 8.8910e-2 kg m^-3.
  EXPECT_NEAR(us76::temperature_K(20000.0), 216.650, 1e-3);
  EXPECT_LT(rel(us76::pressure_Pa(20000.0), 5.5293e3), 1e-4);
  EXPECT_LT(rel(us76::mass_density_kg_per_m3(20000.0), 8.8910e-2), 1e-4);
}

TEST(Us76, LayerBaseAt47KmGeopotential) {
  // The standard's layer table: at H = 47 km' (Z = 47 350.1 m), T_M = 270.65 K, P_b = 110.9063 Pa.
  EXPECT_NEAR(us76::geopotential_altitude_m(47350.1), 47000.0, 0.1);
  EXPECT_NEAR(us76::temperature_K(47350.1), 270.65, 1e-3);
  EXPECT_LT(rel(us76::pressure_Pa(47350.1), 110.9063), 1e-5);
}

TEST(Us76, PublishedValuesAt86Km) {
  // US76 Table I, Z = 86 km: T = 186.87 K, P = 3.7338e-1 Pa, rho = 6.958e-6 kg m^-3, n = 1.447e20 m^-3.
  EXPECT_NEAR(us76::temperature_K(86000.0), 186.87, 0.01);
  EXPECT_LT(rel(us76::pressure_Pa(86000.0), 3.7338e-1), 1e-4);
  EXPECT_LT(rel(us76::mass_density_kg_per_m3(86000.0), 6.958e-6), 1e-3);
  EXPECT_LT(rel(us76::number_density_per_m3(86000.0), 1.447e20), 1e-3);
}

TEST(Us76, MatchesIndependentlyComputedTableEvery100m) {
  const auto t = CsvTable::embedded("us_standard_atmosphere_1976.csv");
  const auto& z = t.column("altitude_m");
  for (std::size_t i = 0; i < t.rows(); ++i) {
    SCOPED_TRACE(z[i]);
    EXPECT_NEAR(us76::temperature_K(z[i]), t.column("temperature_K")[i], 2e-4);
    EXPECT_LT(rel(us76::pressure_Pa(z[i]), t.column("pressure_Pa")[i]), 2e-6);
    EXPECT_LT(rel(us76::number_density_per_m3(z[i]), t.column("number_density_m3")[i]), 2e-6);
    EXPECT_LT(rel(us76::mass_density_kg_per_m3(z[i]), t.column("density_kg_m3")[i]), 2e-6);
  }
}

TEST(Us76, ContinuousAndFallingAbove86Km) {
  // The AFGL continuation meets the standard at 86 km and keeps falling to the
  // top of any atmosphere (extrapolated beyond 120 km).
  EXPECT_LT(rel(us76::number_density_per_m3(86000.0 + 1e-6), us76::number_density_per_m3(86000.0)), 1e-6);
  double prev = us76::number_density_per_m3(0.0);
  for (double z = 50.0; z <= 300000.0; z += 50.0) {
    const double n = us76::number_density_per_m3(z);
    ASSERT_LT(n, prev) << z;
    ASSERT_GT(n, 0.0) << z;
    prev = n;
  }
  // AFGL at 100 km: n = 1.189e19 m^-3; our scaled continuation stays within 5 %.
  EXPECT_LT(rel(us76::number_density_per_m3(100000.0), 1.189e19), 0.05);
}

TEST(Us76, NegativeAltitudeReadsAsGround) {
  EXPECT_DOUBLE_EQ(us76::number_density_per_m3(-1e-9), us76::number_density_per_m3(0.0));
}

}  // namespace
}  // namespace skyfarm

// Oracles for the optical-constant types: published indices from the
// Sellmeier coefficient files (Schott's N-BK7 n_d and Abbe number, Malitson's
// fused silica, Daimon's water), closed forms (a one-term formula, the
// normal-incidence reflectance), exact interpolation at and between table
// points, clamping outside the data, and every validation rule's message.
#include "common/material/optical_constants.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/data/embedded_files.h"

namespace skyfarm::material {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

SellmeierDispersion embedded_sellmeier(const std::string& file) {
  return SellmeierDispersion::parse_coefficients(embedded_file(file), file);
}

// `f` throws E whose message contains every one of `parts`.
template <class E = std::invalid_argument>
void expect_throw_with(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one containing \"" << parts.front() << "\"";
  } catch (const E& e) {
    const std::string what = e.what();
    for (const std::string& part : parts)
      EXPECT_NE(what.find(part), std::string::npos) << "message \"" << what << "\" lacks \"" << part << "\"";
  }
}

// Schott's catalogue: N-BK7 n_d = 1.51680 at the helium d line 587.5618 nm
// and V_d = (n_d − 1)/(n_F − n_C) = 64.17 (F 486.1327 nm, C 656.2725 nm).
TEST(Sellmeier, Bk7SchottIndexAndAbbeNumber) {
  const SellmeierDispersion bk7 = embedded_sellmeier("glass_n_bk7_sellmeier_schott.csv");
  ASSERT_EQ(bk7.terms().size(), 3u);
  const double nd = bk7.n(587.5618);
  EXPECT_NEAR(nd, 1.5168, 5e-5);
  const double vd = (nd - 1.0) / (bk7.n(486.1327) - bk7.n(656.2725));
  EXPECT_NEAR(vd, 64.17, 0.01);
  EXPECT_DOUBLE_EQ(bk7.min_wavelength_nm(), 300.0);
  EXPECT_DOUBLE_EQ(bk7.max_wavelength_nm(), 2500.0);
}

// Malitson (1965): fused silica n = 1.4585 at 587.6 nm.  The file gives the
// resonance wavelengths λᵢ, which enter squared: reading them as Cᵢ would
// give n ≈ 1.565 there.
TEST(Sellmeier, FusedSilicaMalitson) {
  const SellmeierDispersion silica = embedded_sellmeier("fused_silica_sellmeier_malitson1965.csv");
  ASSERT_EQ(silica.terms().size(), 3u);
  EXPECT_NEAR(silica.terms()[0].c_um2, 0.0684043 * 0.0684043, 1e-15);
  EXPECT_NEAR(silica.n(587.6), 1.4585, 5e-5);
  // Normal dispersion: the index falls with wavelength over the visible.
  EXPECT_GT(silica.n(400.0), silica.n(550.0));
  EXPECT_GT(silica.n(550.0), silica.n(800.0));
}

// Daimon & Masumura (2007), 20 °C: water n = 1.333 at the sodium D line.
TEST(Sellmeier, WaterDaimonMasumura) {
  const SellmeierDispersion water = embedded_sellmeier("water_sellmeier_daimon_masumura2007_20C.csv");
  ASSERT_EQ(water.terms().size(), 4u);
  EXPECT_NEAR(water.n(589.0), 1.333, 1e-3);
  EXPECT_NEAR(water.n(589.0), 1.33336, 2e-5);
}

// The embedded files in `coefficient,value` form are exactly the three
// Sellmeier fits, and each parses (the numeric-table check skips them).
TEST(Sellmeier, EveryEmbeddedCoefficientFileParses) {
  std::vector<std::string> found;
  for (const std::string& name : embedded_file_names()) {
    if (!embedded_file(name).starts_with("coefficient,value\n")) continue;
    found.push_back(name);
    EXPECT_NO_THROW(embedded_sellmeier(name)) << name;
  }
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, (std::vector<std::string>{"fused_silica_sellmeier_malitson1965.csv",
                                             "glass_n_bk7_sellmeier_schott.csv",
                                             "water_sellmeier_daimon_masumura2007_20C.csv"}));
}

// B = 1, C = 0: n² = 1 + 1 at every wavelength.
TEST(Sellmeier, OneTermClosedForm) {
  const SellmeierDispersion s({{1.0, 0.0}}, 300.0, 900.0, "test");
  for (double lambda : {300.0, 512.3, 900.0}) EXPECT_DOUBLE_EQ(s.n(lambda), std::sqrt(2.0));
  // B = 0.5, C = 0.01 µm² at 500 nm: n² = 1 + 0.5·0.25/0.24.
  const SellmeierDispersion t({{0.5, 0.01}}, 300.0, 900.0, "test");
  EXPECT_NEAR(t.n(500.0), std::sqrt(1.0 + 0.5 * 0.25 / 0.24), 1e-15);
}

TEST(Sellmeier, ClampsOutsideItsRange) {
  const SellmeierDispersion bk7 = embedded_sellmeier("glass_n_bk7_sellmeier_schott.csv");
  EXPECT_EQ(bk7.n(100.0), bk7.n(300.0));
  EXPECT_EQ(bk7.n(10000.0), bk7.n(2500.0));
  EXPECT_NE(bk7.n(300.0), bk7.n(2500.0));
}

TEST(Sellmeier, RejectsInvalidFormulas) {
  expect_throw_with([] { SellmeierDispersion({}, 300.0, 900.0, "glass"); }, {"glass", "at least one term"});
  expect_throw_with([] { SellmeierDispersion({{kNaN, 0.0}}, 300.0, 900.0, "glass"); }, {"glass", "not finite"});
  expect_throw_with([] { SellmeierDispersion({{1.0, 0.0}}, 900.0, 300.0, "glass"); }, {"glass", "0 < min < max"});
  expect_throw_with([] { SellmeierDispersion({{1.0, 0.0}}, 0.0, 300.0, "glass"); }, {"glass", "0 < min < max"});
  // C = 0.25 µm²: a pole at 500 nm.
  expect_throw_with([] { SellmeierDispersion({{1.0, 0.25}}, 300.0, 900.0, "glass"); }, {"glass", "pole at 500"});
  // B = −2: n² = −1 everywhere.
  expect_throw_with([] { SellmeierDispersion({{-2.0, 0.0}}, 300.0, 900.0, "glass"); }, {"glass", "n² <= 0"});
}

TEST(Sellmeier, ParseErrorsNameTheSource) {
  using E = std::runtime_error;
  expect_throw_with<E>([] { SellmeierDispersion::parse_coefficients("a,b\nB1,1\n", "f.csv"); },
                       {"f.csv", "coefficient,value"});
  expect_throw_with<E>(
      [] { SellmeierDispersion::parse_coefficients("coefficient,value\nB1,x\n", "f.csv"); },
      {"f.csv:2", "`x` is not a number"});
  expect_throw_with<E>(
      [] {
        SellmeierDispersion::parse_coefficients(
            "coefficient,value\nB1,1\nwavelength_min_um,0.3\nwavelength_max_um,1\n", "f.csv");
      },
      {"f.csv", "missing coefficient `lambda1_um`"});
  expect_throw_with<E>(
      [] { SellmeierDispersion::parse_coefficients("coefficient,value\nB1,1\nC1_um2,0\n", "f.csv"); },
      {"f.csv", "missing coefficient `wavelength_min_um`"});
}

TEST(ComplexIor, NormalIncidenceReflectance) {
  EXPECT_DOUBLE_EQ(normal_incidence_reflectance({1.0, 0.0}), 0.0);
  EXPECT_NEAR(normal_incidence_reflectance({1.5, 0.0}), 0.04, 1e-15);
  // ((n−1)² + k²)/((n+1)² + k²) for gold at 548.6 nm (Johnson & Christy).
  EXPECT_NEAR(normal_incidence_reflectance({0.43, 2.455}), (0.57 * 0.57 + 2.455 * 2.455) / (1.43 * 1.43 + 2.455 * 2.455),
              1e-15);
  EXPECT_GT(normal_incidence_reflectance({0.05, 100.0}), 0.9999);
  const ComplexIor ior{0.43, 2.455};
  EXPECT_EQ(ior.eta(), std::complex<double>(0.43, 2.455));
}

TEST(SpectralIor, TableIsExactAtNodesLinearBetweenAndClampedOutside) {
  const std::vector<double> wl = {400.0, 500.0, 700.0};
  const std::vector<double> n = {1.2, 0.8, 0.4};
  const std::vector<double> k = {2.0, 3.0, 5.0};
  const SpectralIor ior = SpectralIor::tabulated(wl, n, k, "metal");
  EXPECT_FALSE(ior.has_sellmeier());
  for (std::size_t i = 0; i < wl.size(); ++i) {
    EXPECT_EQ(ior.n(wl[i]), n[i]);
    EXPECT_EQ(ior.k(wl[i]), k[i]);
  }
  EXPECT_NEAR(ior.n(450.0), 1.0, 1e-15);
  EXPECT_NEAR(ior.k(450.0), 2.5, 1e-15);
  EXPECT_NEAR(ior.n(650.0), 0.5, 1e-15);
  EXPECT_NEAR(ior.k(650.0), 4.5, 1e-15);
  const ComplexIor at = ior.at(600.0);
  EXPECT_NEAR(at.n, 0.6, 1e-15);
  EXPECT_NEAR(at.k, 4.0, 1e-15);
  // Held at the end values, not extrapolated (a line would give k < 0 or n < 0).
  EXPECT_EQ(ior.n(360.0), 1.2);
  EXPECT_EQ(ior.k(360.0), 2.0);
  EXPECT_EQ(ior.n(830.0), 0.4);
  EXPECT_EQ(ior.k(830.0), 5.0);
  EXPECT_TRUE(ior.covers(400.0, 700.0));
  EXPECT_FALSE(ior.covers(360.0, 700.0));
  EXPECT_FALSE(ior.covers(400.0, 830.0));
}

TEST(SpectralIor, SellmeierWithAndWithoutK) {
  const SpectralIor glass = SpectralIor::sellmeier(embedded_sellmeier("glass_n_bk7_sellmeier_schott.csv"),
                                                   {300.0, 1000.0}, {1e-8, 3e-8}, "bk7");
  EXPECT_TRUE(glass.has_sellmeier());
  EXPECT_NEAR(glass.n(587.5618), 1.5168, 5e-5);
  EXPECT_NEAR(glass.k(650.0), 2e-8, 1e-20);
  EXPECT_TRUE(glass.covers(360.0, 830.0));
  EXPECT_FALSE(glass.covers(360.0, 2000.0));  // k stops at 1000 nm

  const SpectralIor clear = SpectralIor::sellmeier(embedded_sellmeier("fused_silica_sellmeier_malitson1965.csv"));
  EXPECT_EQ(clear.k(360.0), 0.0);
  EXPECT_EQ(clear.k(830.0), 0.0);
  EXPECT_TRUE(clear.covers(360.0, 830.0));
  EXPECT_FALSE(clear.covers(100.0, 830.0));  // Malitson's fit starts at 210 nm
}

TEST(SpectralIor, EachValidationRuleThrowsWithItsMessage) {
  const auto make = [](std::vector<double> wl, std::vector<double> n, std::vector<double> k) {
    return [=] { SpectralIor::tabulated(wl, n, k, "my_metal"); };
  };
  expect_throw_with(make({}, {}, {}), {"my_metal", "wavelengths_nm is empty"});
  expect_throw_with(make({400, kNaN}, {1, 1}, {0, 0}), {"my_metal", "wavelengths_nm[1] = nan", "not finite"});
  expect_throw_with(make({-5, 400}, {1, 1}, {0, 0}), {"my_metal", "wavelengths_nm[0] = -5", "must be > 0"});
  expect_throw_with(make({400, 500, 500}, {1, 1, 1}, {0, 0, 0}),
                    {"my_metal", "increase strictly", "wavelengths_nm[2] = 500", "wavelengths_nm[1] = 500"});
  expect_throw_with(make({400, 600, 500}, {1, 1, 1}, {0, 0, 0}), {"my_metal", "increase strictly"});
  expect_throw_with(make({400, 500}, {1, 1, 1}, {0, 0}), {"my_metal", "n has 3 values for 2 wavelengths"});
  expect_throw_with(make({400, 500}, {1, 1}, {0}), {"my_metal", "k has 1 values for 2 wavelengths"});
  expect_throw_with(make({400, 500}, {1, kNaN}, {0, 0}), {"my_metal", "n[1] = nan", "not finite"});
  expect_throw_with(make({400, 500}, {1, std::numeric_limits<double>::infinity()}, {0, 0}),
                    {"my_metal", "n[1] = inf", "not finite"});
  expect_throw_with(make({400, 500}, {1, 0}, {0, 0}), {"my_metal", "n[1] = 0", "must be > 0"});
  expect_throw_with(make({400, 500}, {-1, 1}, {0, 0}), {"my_metal", "n[0] = -1", "must be > 0"});
  expect_throw_with(make({400, 500}, {1, 1}, {0, -0.5}), {"my_metal", "k[1] = -0.5", "must be >= 0"});
  expect_throw_with(make({400, 500}, {1, 1}, {kNaN, 0}), {"my_metal", "k[0] = nan", "not finite"});
  // The Sellmeier form checks its k table the same way.
  expect_throw_with(
      [] {
        SpectralIor::sellmeier(SellmeierDispersion({{1.0, 0.0}}, 300.0, 900.0, "g"), {400, 500}, {0, -1}, "my_glass");
      },
      {"my_glass", "k[1] = -1", "must be >= 0"});
  // A valid table of one point is a constant.
  const SpectralIor one = SpectralIor::tabulated({550.0}, {1.5}, {0.0}, "constant");
  EXPECT_EQ(one.n(360.0), 1.5);
  EXPECT_EQ(one.n(830.0), 1.5);
  EXPECT_TRUE(one.covers(360.0, 830.0));
}

TEST(SpectralAlbedo, TableValidationAndEvaluation) {
  const SpectralAlbedo a({400.0, 600.0}, {0.2, 0.6}, "ground");
  EXPECT_EQ(a.at(400.0), 0.2);
  EXPECT_NEAR(a.at(500.0), 0.4, 1e-15);
  EXPECT_EQ(a.at(360.0), 0.2);
  EXPECT_EQ(a.at(830.0), 0.6);
  EXPECT_EQ(a.table().x().size(), 2u);
  EXPECT_TRUE(a.covers(400.0, 600.0));
  EXPECT_FALSE(a.covers(360.0, 830.0));
  // The limits themselves are valid.
  EXPECT_NO_THROW(SpectralAlbedo({400.0, 600.0}, {0.0, 1.0}, "ground"));

  const auto make = [](std::vector<double> wl, std::vector<double> albedo) {
    return [=] { SpectralAlbedo(wl, albedo, "my_ground"); };
  };
  expect_throw_with(make({400, 500}, {0.5, 1.2}), {"my_ground", "albedo[1] = 1.2", "must lie in [0, 1]"});
  expect_throw_with(make({400, 500}, {-0.1, 0.5}), {"my_ground", "albedo[0] = -0.1", "must lie in [0, 1]"});
  expect_throw_with(make({400, 500}, {0.5, kNaN}), {"my_ground", "albedo[1] = nan", "not finite"});
  expect_throw_with(make({400, 500}, {0.5}), {"my_ground", "albedo has 1 values for 2 wavelengths"});
  expect_throw_with(make({500, 400}, {0.5, 0.5}), {"my_ground", "increase strictly"});
  expect_throw_with(make({}, {}), {"my_ground", "empty"});
}

}  // namespace
}  // namespace skyfarm::material

// Oracles for the named materials: published values at a few wavelengths
// (Schott's BK7 n_d, Malitson's fused silica, water at the sodium D line,
// Johnson & Christy's gold at a tabulated wavelength, silver's reflectance),
// the water formula against the independent water table, the physical
// shape of the grounds (snow bright, grass green), every name resolving,
// the unknown-name message, and custom materials' validation.
#include "common/material/material_library.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "common/core/constants.h"
#include "common/data/csv_table.h"

namespace skyfarm::material {
namespace {

constexpr double kMin_nm = 360.0, kMax_nm = 830.0;

template <class E = std::invalid_argument, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return {};
}

TEST(MaterialLibrary, EveryNameResolvesToPhysicalConstants) {
  std::set<std::string> seen;
  ASSERT_EQ(all_material_ids().size(), 14u);
  for (const MaterialId id : all_material_ids()) {
    const std::string name(material_name(id));
    SCOPED_TRACE(name);
    EXPECT_TRUE(seen.insert(name).second) << "duplicate name";
    ASSERT_EQ(find_material(name), id);
    const Material& m = named_material(name);
    EXPECT_EQ(&m, &named_material(id));
    EXPECT_EQ(m.name(), name);
    for (double lambda = kMin_nm; lambda <= kMax_nm; lambda += 5.0) {
      if (m.has_ior()) {
        const ComplexIor ior = m.ior().at(lambda);
        ASSERT_TRUE(std::isfinite(ior.n) && ior.n > 0.0) << lambda;
        ASSERT_TRUE(std::isfinite(ior.k) && ior.k >= 0.0) << lambda;
      } else {
        const double a = m.albedo().at(lambda);
        ASSERT_TRUE(a >= 0.0 && a <= 1.0) << lambda;
      }
    }
  }
  const std::set<std::string> expected = {"gold", "silver", "copper", "aluminium", "chrome", "water", "ice", "bk7",
                                          "fused_silica", "grass", "sand", "loam", "concrete", "snow"};
  EXPECT_EQ(seen, expected);
}

TEST(MaterialLibrary, KindsAndWhereTheDataLies) {
  for (const char* metal : {"gold", "silver", "copper", "aluminium"}) {
    SCOPED_TRACE(metal);
    EXPECT_EQ(named_material(metal).kind(), MaterialKind::kConductor);
    EXPECT_TRUE(named_material(metal).ior().covers(kMin_nm, kMax_nm));
  }
  for (const char* dielectric : {"water", "ice", "bk7", "fused_silica"}) {
    SCOPED_TRACE(dielectric);
    EXPECT_EQ(named_material(dielectric).kind(), MaterialKind::kDielectric);
    EXPECT_TRUE(named_material(dielectric).ior().covers(kMin_nm, kMax_nm));
  }
  for (const char* ground : {"grass", "sand", "loam", "concrete"}) {
    SCOPED_TRACE(ground);
    EXPECT_EQ(named_material(ground).kind(), MaterialKind::kDiffuse);
    // Feister and Grewe's tables stop at 800 nm; above it the value is held.
    EXPECT_TRUE(named_material(ground).albedo().covers(kMin_nm, 800.0));
    EXPECT_FALSE(named_material(ground).albedo().covers(kMin_nm, kMax_nm));
    EXPECT_EQ(named_material(ground).albedo().at(kMax_nm), named_material(ground).albedo().at(800.0));
  }
  // Bowker's snow starts at 390 nm.
  EXPECT_TRUE(named_material("snow").albedo().covers(390.0, kMax_nm));
  EXPECT_FALSE(named_material("snow").albedo().covers(kMin_nm, kMax_nm));
  EXPECT_EQ(named_material("snow").albedo().at(kMin_nm), named_material("snow").albedo().at(390.0));

  EXPECT_NE(message_of<std::logic_error>([] { (void)named_material("snow").ior(); }).find("snow"), std::string::npos);
  EXPECT_NE(message_of<std::logic_error>([] { (void)named_material("gold").albedo(); }).find("gold"),
            std::string::npos);
}

TEST(MaterialLibrary, UnknownNameListsTheKnownOnes) {
  EXPECT_FALSE(find_material("unobtainium"));
  EXPECT_FALSE(find_material("Gold"));  // names are exact
  const std::string msg = message_of([] { (void)named_material("unobtainium"); });
  EXPECT_NE(msg.find("unknown material \"unobtainium\""), std::string::npos) << msg;
  for (const MaterialId id : all_material_ids())
    EXPECT_NE(msg.find(std::string(material_name(id))), std::string::npos) << msg;
  EXPECT_EQ(known_material_names(),
            "gold, silver, copper, aluminium, chrome, water, ice, bk7, fused_silica, grass, sand, loam, concrete, snow");
}

// Johnson & Christy (1972) Table I: gold at 2.26 eV (548.6 nm) n = 0.43,
// k = 2.455, and at 2.13 eV (582.1 nm) n = 0.29, k = 2.863.
TEST(MaterialLibrary, GoldEqualsItsTableAtNodesAndInterpolatesBetween) {
  const SpectralIor& gold = named_material("gold").ior();
  EXPECT_EQ(gold.n(548.6), 0.43);
  EXPECT_EQ(gold.k(548.6), 2.455);
  EXPECT_EQ(gold.n(582.1), 0.29);
  EXPECT_EQ(gold.k(582.1), 2.863);
  const double mid = 0.5 * (548.6 + 582.1);
  EXPECT_NEAR(gold.n(mid), 0.5 * (0.43 + 0.29), 1e-12);
  EXPECT_NEAR(gold.k(mid), 0.5 * (2.455 + 2.863), 1e-12);
  // Every row of the embedded table is reproduced exactly.
  const CsvTable t = CsvTable::embedded("metal_nk_au_johnson_christy1972.csv");
  for (std::size_t i = 0; i < t.rows(); ++i) {
    EXPECT_EQ(gold.n(t.column("wavelength_nm")[i]), t.column("n_1")[i]);
    EXPECT_EQ(gold.k(t.column("wavelength_nm")[i]), t.column("k_1")[i]);
  }
  // Gold's colour: it reflects red far better than blue.
  EXPECT_GT(normal_incidence_reflectance(gold.at(650.0)), 0.9);
  EXPECT_LT(normal_incidence_reflectance(gold.at(450.0)), 0.5);
}

// Chromium is a poor mirror next to silver: Johnson & Christy (1974) give a
// normal-incidence reflectance of about 0.5-0.57 across the visible (other
// film preparations reach 0.64-0.70, data/README.md).
TEST(MaterialLibrary, ChromeReflectsAboutHalfAtNormalIncidence) {
  for (double nm : {400.0, 550.0, 700.0}) {
    const double r = normal_incidence_reflectance(named_material("chrome").ior().at(nm));
    EXPECT_GT(r, 0.48) << nm;
    EXPECT_LT(r, 0.60) << nm;
  }
}

// Silver is the best visible mirror: R₀ = ((n−1)² + k²)/((n+1)² + k²) > 0.95
// at 600 nm (Johnson & Christy give about 0.987).
TEST(MaterialLibrary, SilverReflectsMoreThan95PercentAt600nm) {
  const double r = normal_incidence_reflectance(named_material("silver").ior().at(600.0));
  EXPECT_GT(r, 0.95);
  EXPECT_LT(r, 1.0);
}

TEST(MaterialLibrary, CopperAndAluminiumReflectances) {
  // Copper's red: R₀ rises from about 0.6 at 550 nm to above 0.9 at 650 nm.
  const SpectralIor& cu = named_material("copper").ior();
  EXPECT_LT(normal_incidence_reflectance(cu.at(550.0)), 0.7);
  EXPECT_GT(normal_incidence_reflectance(cu.at(650.0)), 0.9);
  // Aluminium is a flat, bright grey, with its interband dip near 800 nm.
  const SpectralIor& al = named_material("aluminium").ior();
  for (double lambda = kMin_nm; lambda <= kMax_nm; lambda += 10.0)
    EXPECT_NEAR(normal_incidence_reflectance(al.at(lambda)), 0.9, 0.04) << lambda;
  EXPECT_LT(normal_incidence_reflectance(al.at(815.0)), normal_incidence_reflectance(al.at(500.0)));
}

TEST(MaterialLibrary, PublishedIndicesOfTheDielectrics) {
  // Schott N-BK7 n_d = 1.5168 at 587.56 nm.
  EXPECT_NEAR(named_material("bk7").ior().n(587.5618), 1.5168, 5e-5);
  // Malitson: fused silica 1.4585 at 587.6 nm, transparent.
  EXPECT_NEAR(named_material("fused_silica").ior().n(587.6), 1.4585, 5e-5);
  EXPECT_EQ(named_material("fused_silica").ior().k(587.6), 0.0);
  // Water 1.333 at 589 nm.
  EXPECT_NEAR(named_material("water").ior().n(589.0), 1.333, 1e-3);
  // Warren & Brandt: ice 1.3110 at 550 nm (a table point), below water.
  EXPECT_EQ(named_material("ice").ior().n(550.0), 1.3110);
  EXPECT_LT(named_material("ice").ior().n(550.0), named_material("water").ior().n(550.0));
}

// Absorption of the dielectrics, from k: α = 4πk/λ.
TEST(MaterialLibrary, DielectricAbsorption) {
  // Water's k is Hale & Querry's: 1.96e-9 at 550 nm, and water absorbs red
  // more than blue (α = 0.045 m⁻¹ at 550 nm, 0.32 m⁻¹ at 650 nm).
  const SpectralIor& water = named_material("water").ior();
  EXPECT_EQ(water.k(550.0), 1.96e-9);
  const auto alpha_per_m = [](const SpectralIor& ior, double lambda_nm) {
    return 4.0 * kPi * ior.k(lambda_nm) / (lambda_nm * 1e-9);
  };
  EXPECT_NEAR(alpha_per_m(water, 550.0), 0.0448, 0.001);
  EXPECT_GT(alpha_per_m(water, 650.0), 5.0 * alpha_per_m(water, 450.0));
  // N-BK7's internal transmittance through 10 mm stays above 0.99 in the visible.
  const SpectralIor& bk7 = named_material("bk7").ior();
  for (double lambda : {450.0, 550.0, 650.0})
    EXPECT_GT(std::exp(-alpha_per_m(bk7, lambda) * 0.01), 0.99) << lambda;
}

// The water formula (Daimon & Masumura, 20 °C) and the water table (Hale &
// Querry, 25 °C) are independent measurements: they agree to 0.006 over
// 360-830 nm and to 0.002 from 500 nm on (the table's n has 3 decimals;
// the 5 K between them is about 5e-4).
TEST(MaterialLibrary, WaterFormulaAgreesWithTheWaterTable) {
  const SpectralIor& formula = named_material("water").ior();
  ASSERT_TRUE(formula.has_sellmeier());
  const CsvTable t = CsvTable::embedded("water_nk_hale_querry1973.csv");
  const SpectralIor table = SpectralIor::tabulated(t.column("wavelength_nm"), t.column("n_1"), t.column("k_1"),
                                                   "water (Hale & Querry)");
  for (double lambda = kMin_nm; lambda <= kMax_nm; lambda += 5.0) {
    const double d = std::abs(formula.n(lambda) - table.n(lambda));
    EXPECT_LT(d, 0.0065) << lambda;
    if (lambda >= 500.0) {
      EXPECT_LT(d, 0.002) << lambda;
    }
  }
}

// Bowker's fresh snow: above 0.9 through the middle of the visible and above
// 0.85 at every wavelength (its blue end, 0.853 at 390 nm, is the lowest).
TEST(MaterialLibrary, SnowIsBright) {
  const SpectralAlbedo& snow = named_material("snow").albedo();
  for (double lambda = 510.0; lambda <= 770.0; lambda += 5.0) EXPECT_GT(snow.at(lambda), 0.9) << lambda;
  for (double lambda = kMin_nm; lambda <= kMax_nm; lambda += 5.0) EXPECT_GT(snow.at(lambda), 0.85) << lambda;
  // Brighter than every other ground everywhere.
  for (const char* ground : {"grass", "sand", "loam", "concrete"})
    for (double lambda = kMin_nm; lambda <= 800.0; lambda += 10.0)
      EXPECT_GT(snow.at(lambda), named_material(ground).albedo().at(lambda)) << ground << " " << lambda;
}

// Chlorophyll absorbs blue and red: grass reflects more at 550 nm than at 450
// and 670 nm, and far more in the near infrared (the red edge near 700 nm).
TEST(MaterialLibrary, GrassHasItsGreenBumpAndRedEdge) {
  const SpectralAlbedo& grass = named_material("grass").albedo();
  EXPECT_GT(grass.at(550.0), grass.at(450.0));
  EXPECT_GT(grass.at(550.0), grass.at(670.0));
  EXPECT_GT(grass.at(800.0), 3.0 * grass.at(550.0));
}

TEST(MaterialLibrary, GroundsAtTheirPublishedValues) {
  // Feister & Grewe at 550 nm (table points): sand 0.324, grass 0.089,
  // loam 0.158, dry concrete 0.236.
  EXPECT_EQ(named_material("sand").albedo().at(550.0), 0.324);
  EXPECT_EQ(named_material("grass").albedo().at(550.0), 0.089);
  EXPECT_EQ(named_material("loam").albedo().at(550.0), 0.158);
  EXPECT_EQ(named_material("concrete").albedo().at(550.0), 0.236);
  EXPECT_EQ(named_material("snow").albedo().at(550.0), 0.906);
}

TEST(MaterialLibrary, CustomMaterialsAreValidated) {
  const Material mirror = custom_ior_material("my_mirror", MaterialKind::kConductor, {400.0, 700.0}, {0.1, 0.2},
                                              {3.0, 4.0});
  EXPECT_EQ(mirror.name(), "my_mirror");
  EXPECT_EQ(mirror.kind(), MaterialKind::kConductor);
  EXPECT_NEAR(mirror.ior().k(550.0), 3.5, 1e-15);

  const Material ground = custom_albedo_material("my_ground", {400.0, 700.0}, {0.1, 0.4});
  EXPECT_EQ(ground.kind(), MaterialKind::kDiffuse);
  EXPECT_NEAR(ground.albedo().at(550.0), 0.25, 1e-15);

  std::string msg = message_of([] {
    (void)custom_ior_material("my_mirror", MaterialKind::kConductor, {400.0, 700.0}, {0.1, 0.2}, {3.0, -4.0});
  });
  EXPECT_NE(msg.find("my_mirror: k[1] = -4 must be >= 0"), std::string::npos) << msg;
  msg = message_of([] {
    (void)custom_ior_material("my_mirror", MaterialKind::kConductor, {700.0, 400.0}, {0.1, 0.2}, {3.0, 4.0});
  });
  EXPECT_NE(msg.find("my_mirror: wavelengths_nm must increase strictly"), std::string::npos) << msg;
  msg = message_of([] {
    (void)custom_ior_material("my_mirror", MaterialKind::kDiffuse, {400.0, 700.0}, {0.1, 0.2}, {3.0, 4.0});
  });
  EXPECT_NE(msg.find("my_mirror"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not diffuse"), std::string::npos) << msg;
  msg = message_of([] { (void)custom_albedo_material("my_ground", {400.0, 700.0}, {0.1, 1.5}); });
  EXPECT_NE(msg.find("my_ground: albedo[1] = 1.5 must lie in [0, 1]"), std::string::npos) << msg;
  msg = message_of([] { (void)custom_albedo_material("my_ground", {400.0, 700.0, 800.0}, {0.1, 0.5}); });
  EXPECT_NE(msg.find("my_ground: albedo has 2 values for 3 wavelengths"), std::string::npos) << msg;
}

}  // namespace
}  // namespace skyfarm::material

// Colour management (common/image/color_management.h): the OCIO conversions
// against colours computed directly from the CIE 1931 observer and against
// matrices built from the published primaries; AP0 enclosing the spectral
// locus; the EXR's chromaticities, colour space and units attributes; the
// ACES view of the PNG against the srgb view's clip.
#include "common/image/color_management.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "common/spectrum/cie_observer.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

class ColorManagementFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("skyfarm_color_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

std::array<double, 3> as_array(const Xyz& c) { return {c.x, c.y, c.z}; }

// |a − b| / |b| (Euclidean norms).
double relative_difference(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double d = 0, n = 0;
  for (int i = 0; i < 3; ++i) d += (a[i] - b[i]) * (a[i] - b[i]), n += b[i] * b[i];
  return std::sqrt(d / n);
}

std::array<double, 3> convert(ColorSpace from, ColorSpace to, const std::array<double, 3>& v) {
  float f[3] = {float(v[0]), float(v[1]), float(v[2])};
  convert_color_space(from, to, f, 1);
  return {f[0], f[1], f[2]};
}

// The Bradford chromatic adaptation from white w1 to w2 (Lindbloom,
// "Chromatic Adaptation", brucelindbloom.com; the cone matrix of Lam 1985):
// M = B⁻¹ diag(B w2 / B w1) B.
Matrix3 bradford(Chromaticity w1, Chromaticity w2) {
  constexpr Matrix3 B{{{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
  const auto c1 = mat3_mul(B, xyz_of_chromaticity(w1)), c2 = mat3_mul(B, xyz_of_chromaticity(w2));
  Matrix3 D{};
  for (int i = 0; i < 3; ++i) D[i][i] = c2[i] / c1[i];
  auto mul = [](const Matrix3& a, const Matrix3& b) {
    Matrix3 m{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) m[i][j] += a[i][k] * b[k][j];
    return m;
  };
  return mul(mat3_inverse(B), mul(D, B));
}

Matrix3 xyz_to_rgb_of(const std::array<Chromaticity, 4>& p) {
  return mat3_inverse(rgb_to_xyz_matrix(p[0], p[1], p[2], p[3]));
}

// Monochromatic light on the spectral locus: XYZ = (x̄, ȳ, z̄)(λ) directly
// from the CIE 1931 table; Rec.709 → AP0 → XYZ through OCIO gives it back.
TEST(ColorManagement, SpectralLocusRoundTripsThroughAp0ToTheDirectXyz) {
  for (double nm : {520.0, 610.0}) {
    const Xyz xyz = cie1931_cmf(nm);
    const Rgb rec709 = xyz_to_linear_srgb(xyz);
    // Outside Rec.709 (why a wider space is wanted): a negative channel.
    EXPECT_LT(std::min({rec709.r, rec709.g, rec709.b}), 0.0) << nm;
    const auto ap0 = convert(ColorSpace::kLinRec709, ColorSpace::kAces2065_1, {rec709.r, rec709.g, rec709.b});
    const auto back = convert(ColorSpace::kAces2065_1, ColorSpace::kCieXyz, ap0);
    EXPECT_LT(relative_difference(back, as_array(xyz)), 1e-5) << nm;
    const auto direct = convert(ColorSpace::kLinRec709, ColorSpace::kCieXyz, {rec709.r, rec709.g, rec709.b});
    EXPECT_LT(relative_difference(direct, as_array(xyz)), 1e-5) << nm;
  }
}

// OCIO's builtin ACES transforms against matrices built here from the
// published primaries (ST 2065-1 AP0, S-2014-004 AP1) and a Bradford
// adaptation D65 → ACES white: the same numbers to float precision.
TEST(ColorManagement, AcesConversionsMatchThePublishedPrimariesWithBradford) {
  const Matrix3 cat = bradford(kD65White, kAp0Chromaticities[3]);
  for (const auto& [space, prim] : {std::pair{ColorSpace::kAces2065_1, kAp0Chromaticities},
                                    std::pair{ColorSpace::kAcesCg, kAp1Chromaticities}}) {
    for (const Rgb& c : {Rgb{1, 0, 0}, Rgb{0, 1, 0}, Rgb{0, 0, 1}, Rgb{0.2, 3.0, -0.5}}) {
      const Xyz xyz = linear_srgb_to_xyz(c);
      const auto expected = mat3_mul(xyz_to_rgb_of(prim), mat3_mul(cat, as_array(xyz)));
      const auto got = convert(ColorSpace::kLinRec709, space, {c.r, c.g, c.b});
      EXPECT_LT(relative_difference(got, expected), 1e-5) << name_of(space) << " " << c.r << c.g << c.b;
    }
  }
  // D65 white stays neutral: R = G = B = Y in both ACES spaces.
  for (ColorSpace space : {ColorSpace::kAces2065_1, ColorSpace::kAcesCg}) {
    const auto w = convert(ColorSpace::kLinRec709, space, {100.0, 100.0, 100.0});
    for (double v : w) EXPECT_NEAR(v, 100.0, 1e-3) << name_of(space);
  }
}

// AP0's triangle encloses the spectral locus (ST 2065-1 chose it so): every
// monochromatic colour 380-780 nm in AP0's own coordinates (no adaptation)
// has no negative channel (beyond 1e-6 of X+Y+Z: at 780 nm the locus meets
// the red primary (0.7347, 0.2653) and G, B round to ~0).  After the Bradford
// adaptation the written files use, the adapted locus pokes out by at most
// 0.4 % of X+Y+Z (violet, 380-430 nm; 0.08 % deep red): measured, bounded here.
TEST(ColorManagement, Ap0EnclosesTheSpectralLocus) {
  const Matrix3 to_ap0 = xyz_to_rgb_of(kAp0Chromaticities);
  double worst_adapted = 0.0;
  for (int nm = 380; nm <= 780; ++nm) {
    const Xyz xyz = cie1931_cmf(nm);
    const double sum = xyz.x + xyz.y + xyz.z;
    const auto ap0 = mat3_mul(to_ap0, as_array(xyz));
    EXPECT_GE(std::min({ap0[0], ap0[1], ap0[2]}), -1e-6 * sum) << nm << " nm";
    const Rgb rec709 = xyz_to_linear_srgb(xyz);
    const auto adapted = convert(ColorSpace::kLinRec709, ColorSpace::kAces2065_1, {rec709.r, rec709.g, rec709.b});
    worst_adapted = std::min(worst_adapted, std::min({adapted[0], adapted[1], adapted[2]}) / sum);
  }
  EXPECT_GT(worst_adapted, -0.005);
}

TEST_F(ColorManagementFiles, ExrCarriesThePublishedChromaticitiesAndTheColourSpace) {
  Image img(2, 1);
  img.set_xyz(0, 0, Xyz{95.047, 100.0, 108.883});  // D65 white, 100 cd/m^2
  img.set_xyz(1, 0, Xyz{cie1931_cmf(610.0).x * 1e4, cie1931_cmf(610.0).y * 1e4, cie1931_cmf(610.0).z * 1e4});
  struct Case {
    ColorSpace space;
    std::array<Chromaticity, 4> published;
  };
  // AP0: SMPTE ST 2065-1; AP1: Academy S-2014-004; XYZ: OpenEXR's convention.
  const Case cases[] = {
      {ColorSpace::kAces2065_1, {{{0.7347, 0.2653}, {0.0, 1.0}, {0.0001, -0.077}, {0.32168, 0.33767}}}},
      {ColorSpace::kAcesCg, {{{0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, {0.32168, 0.33767}}}},
      {ColorSpace::kCieXyz, {{{1.0, 0.0}, {0.0, 1.0}, {0.0, 0.0}, {1.0 / 3, 1.0 / 3}}}},
      {ColorSpace::kLinRec709, {{{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290}}}},
  };
  for (const Case& c : cases) {
    const fs::path path = dir_ / (std::string(name_of(c.space)) + ".exr");
    write_exr(img, path, {.half = false, .color_space = c.space});
    const ExrFile f = read_exr(path);
    ASSERT_TRUE(f.chromaticities.has_value());
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR((*f.chromaticities)[i].x, c.published[i].x, 1e-7) << name_of(c.space) << " " << i;
      EXPECT_NEAR((*f.chromaticities)[i].y, c.published[i].y, 1e-7) << name_of(c.space) << " " << i;
    }
    if (c.space == ColorSpace::kLinRec709) {
      EXPECT_FALSE(f.string_attributes.contains("skyfarm:color_space"));
      continue;
    }
    EXPECT_EQ(f.string_attributes.at("skyfarm:color_space"), name_of(c.space));
    // The file's RGB through its own chromaticities (OpenEXR's RGBtoXYZ
    // meaning) gives the pixel's XYZ back, adapted to the file's white.
    // (XYZ's primaries have y = 0 for blue: the RGB-to-XYZ matrix is the identity.)
    const auto& p = *f.chromaticities;
    const Matrix3 identity{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    const bool xyz_file = c.space == ColorSpace::kCieXyz;
    const Matrix3 to_xyz = xyz_file ? identity : rgb_to_xyz_matrix(p[0], p[1], p[2], p[3]);
    const Matrix3 cat = xyz_file ? identity : bradford(kD65White, p[3]);
    for (int x = 0; x < 2; ++x) {
      const auto rgb709 = img.rgb(x, 0);
      const auto xyz = linear_srgb_to_xyz(Rgb{rgb709[0], rgb709[1], rgb709[2]});
      const std::array<double, 3> file_rgb{f.channels.at("R").values[x], f.channels.at("G").values[x],
                                           f.channels.at("B").values[x]};
      EXPECT_LT(relative_difference(mat3_mul(to_xyz, file_rgb), mat3_mul(cat, as_array(xyz))), 1e-5)
          << name_of(c.space) << " pixel " << x;
    }
  }
}

TEST_F(ColorManagementFiles, UnitsScaleTheValuesAndSayHowToUndoIt) {
  Image img(4, 1);
  for (int x = 0; x < 4; ++x) img.set_rgb(x, 0, Rgb{1000.0 * (x + 1), 2000.0 * (x + 1), 500.0});
  const double cd_m2 = img.rgb(1, 0)[1];
  // w_m2_sr: cd/m^2 / 683 lm/W.
  write_exr(img, dir_ / "w.exr", {.half = false, .units = RadiometricUnits::kWM2Sr});
  const ExrFile w = read_exr(dir_ / "w.exr");
  EXPECT_NEAR(w.channels.at("G").values[1], cd_m2 / 683.0, 1e-6 * cd_m2 / 683.0);
  EXPECT_EQ(w.string_attributes.at("skyfarm:units"), "w_m2_sr");
  EXPECT_NEAR(w.number_attributes.at("whiteLuminance"), 683.0, 1e-3);
  // relative: times the PNG's exposure scale, automatic (median) or the EV given.
  const double scale = exposure_scale(auto_exposure_ev(img));
  write_exr(img, dir_ / "rel.exr", {.half = false, .units = RadiometricUnits::kRelative});
  const ExrFile rel = read_exr(dir_ / "rel.exr");
  EXPECT_NEAR(rel.channels.at("G").values[1], cd_m2 * scale, 1e-6 * cd_m2 * scale);
  EXPECT_NEAR(rel.number_attributes.at("skyfarm:units_scale"), scale, 1e-12 * scale);
  EXPECT_NEAR(rel.number_attributes.at("whiteLuminance"), 1.0 / scale, 1e-6 / scale);
  write_exr(img, dir_ / "ev.exr", {.half = false, .units = RadiometricUnits::kRelative, .exposure_ev = 12.0});
  EXPECT_NEAR(read_exr(dir_ / "ev.exr").number_attributes.at("skyfarm:units_scale"), exposure_scale(12.0), 1e-15);
  // cd_m2 (default): no units attributes, whiteLuminance 1.
  write_exr(img, dir_ / "abs.exr", {.half = false});
  const ExrFile abs = read_exr(dir_ / "abs.exr");
  EXPECT_FALSE(abs.string_attributes.contains("skyfarm:units"));
  EXPECT_EQ(abs.number_attributes.at("whiteLuminance"), 1.0);
  EXPECT_EQ(abs.channels.at("G").values[1], static_cast<float>(cd_m2));
}

// The srgb view clips: everything above 1 after the exposure is 255.  The
// ACES view rolls off: brighter light stays brighter and below white, and
// scene middle grey shows at ≈ 10 % display luminance (the ACES 1.0 SDR
// reference: 0.18 → 10 nits of 100; 0.104 here, tolerance ±0.02).
TEST_F(ColorManagementFiles, AcesViewDoesNotClipWhereTheSrgbViewDoes) {
  Image img(4, 1);
  // Exposure EV100 = 3 → scale 0.18: pixels at 1, 10, 20, 40 (scene-linear after exposure 0.18, 1.8, 3.6, 7.2).
  const double levels[] = {1.0, 10.0, 20.0, 40.0};
  for (int x = 0; x < 4; ++x) img.set_rgb(x, 0, Rgb{levels[x], levels[x], levels[x]});
  write_png(img, dir_ / "srgb.png", {.exposure_ev = 3.0});
  write_png(img, dir_ / "aces.png", {.exposure_ev = 3.0, .view = DisplayView::kAces});
  const PngFile s = read_png(dir_ / "srgb.png"), a = read_png(dir_ / "aces.png");
  for (int x = 1; x < 4; ++x) EXPECT_EQ(s.rgb[3 * x], 255) << x;
  for (int x = 1; x < 4; ++x) {
    EXPECT_LT(a.rgb[3 * x], 255) << x;
    EXPECT_GT(a.rgb[3 * x], a.rgb[3 * (x - 1)]) << x;
  }
  EXPECT_NEAR(srgb_decode(a.rgb[0] / 255.0), 0.104, 0.02);
  EXPECT_EQ(a.text.at("skyfarm:view"), "aces");
  EXPECT_FALSE(s.text.contains("skyfarm:view"));
  // Saturated colour keeps its hue order (red stays the largest channel).
  Image red(1, 1);
  red.set_rgb(0, 0, Rgb{3.0, 0.5, 0.2});
  write_png(red, dir_ / "red.png", {.exposure_ev = 3.0, .view = DisplayView::kAces});
  const PngFile r = read_png(dir_ / "red.png");
  EXPECT_GT(r.rgb[0], r.rgb[1]);
  EXPECT_GT(r.rgb[1], r.rgb[2]);
}

}  // namespace
}  // namespace skyfarm

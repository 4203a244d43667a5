// Spectral bins and the colour of a binned spectrum (common/lut/spectral_grid.h).
#include "common/lut/spectral_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/core/piecewise_linear.h"
#include "common/spectrum/cie_observer.h"
#include "common/spectrum/color.h"

namespace skyfarm {
namespace {

TEST(LutSpectralGrid, BinsCoverTheRangeEvenly) {
  const SpectralGrid g(360.0, 830.0, 94);
  EXPECT_EQ(g.size(), 94);
  EXPECT_DOUBLE_EQ(g.width_nm(), 5.0);
  EXPECT_DOUBLE_EQ(g.centre_nm(0), 362.5);
  EXPECT_DOUBLE_EQ(g.centre_nm(93), 827.5);
  EXPECT_THROW(SpectralGrid(400.0, 400.0, 4), std::invalid_argument);
  EXPECT_THROW(SpectralGrid(400.0, 700.0, 0), std::invalid_argument);
}

// The mean of a linear function over a bin is its value at the centre; the
// trapezoid lattice is exact for tables with knots on whole nanometres.
TEST(LutSpectralGrid, BinMeanIsExactForPiecewiseLinearTables) {
  const SpectralGrid g(400.0, 700.0, 7);  // width 42.857... nm: bin edges off the lattice
  for (int i = 0; i < g.size(); ++i)
    EXPECT_NEAR(g.bin_mean([](double l) { return 2.0 + 0.01 * l; }, i), 2.0 + 0.01 * g.centre_nm(i), 1e-12);
  const PiecewiseLinear f({400.0, 431.0, 455.5, 700.0}, {1.0, 3.0, 0.5, 2.0});
  const double a = 400.0 + 3 * g.width_nm(), b = a + g.width_nm();
  EXPECT_NEAR(g.bin_mean([&](double l) { return f(l); }, 3), f.integral(a, b) / g.width_nm(), 1e-12);
}

// The weights integrate exactly the piecewise-linear reconstruction: compare
// with spectrum_to_xyz (color.h, exact Simpson on merged knots) of the same
// function written as a PiecewiseLinear table (clamped outside its knots).
TEST(LutSpectralGrid, XyzWeightsMatchSpectrumToXyzOfTheReconstruction) {
  for (int n : {1, 4, 16, 94}) {
    const SpectralGrid g(360.0, 830.0, n);
    std::vector<double> values(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) values[static_cast<std::size_t>(i)] = 1.0 + 0.5 * std::sin(0.7 * i) + 0.001 * i;
    const std::vector<double> centres(g.centres_nm().begin(), g.centres_nm().end());
    const PiecewiseLinear L(centres, values, PiecewiseLinear::Outside::kClamp);
    const Xyz expected = spectrum_to_xyz(L);
    const Xyz got = BinnedSpectrumIntegral(g, 360.0, 830.0).xyz(values);
    EXPECT_NEAR(got.x, expected.x, 1e-10 * expected.y) << n;
    EXPECT_NEAR(got.y, expected.y, 1e-10 * expected.y) << n;
    EXPECT_NEAR(got.z, expected.z, 1e-10 * expected.y) << n;
    const BinnedSpectrumIntegral sub(g, 480.0, 610.0);
    EXPECT_NEAR(sub.band_mean(values), L.integral(480.0, 610.0) / 130.0, 1e-12) << n;
  }
}

// A flat spectrum of 1 W m^-2 sr^-1 nm^-1 has Y = 683 * int ybar = 683 * 106.857 cd/m^2.
TEST(LutSpectralGrid, FlatSpectrumGivesKmTimesTheCmfIntegrals) {
  const SpectralGrid g(360.0, 830.0, 8);
  const std::vector<double> ones(8, 1.0);
  const Xyz c = BinnedSpectrumIntegral(g, 360.0, 830.0).xyz(ones);
  EXPECT_NEAR(c.y, 683.0 * cie1931_ybar_integral_nm(), 1e-9 * c.y);
  EXPECT_NEAR(BinnedSpectrumIntegral(g, 500.0, 520.0).band_mean(ones), 1.0, 1e-14);
}

}  // namespace
}  // namespace skyfarm

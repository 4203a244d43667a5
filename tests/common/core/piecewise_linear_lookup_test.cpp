// PiecewiseLinear::eval finds its interval through a bucket index; these
// tests hold it to the plain binary search it replaced, bit for bit, on the
// tables the renderer evaluates per path and on adversarial ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "common/core/piecewise_linear.h"
#include "common/spectrum/cie_observer.h"
#include "common/sun/solar_spectrum.h"

namespace skyfarm {
namespace {

// eval() as it was: std::upper_bound over all knots.
double reference_eval(const std::vector<double>& x, const std::vector<double>& y, bool zero_outside, double v) {
  if (v <= x.front()) return (v < x.front() && zero_outside) ? 0.0 : y.front();
  if (v >= x.back()) return (v > x.back() && zero_outside) ? 0.0 : y.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), v) - x.begin());
  const double t = (v - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + t * (y[i] - y[i - 1]);
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every knot, its neighbours one ulp away, midpoints and random points.
std::vector<double> probe_points(const std::vector<double>& x, std::mt19937_64& rng) {
  std::vector<double> v;
  for (std::size_t i = 0; i < x.size(); ++i) {
    v.push_back(x[i]);
    v.push_back(std::nextafter(x[i], -INFINITY));
    v.push_back(std::nextafter(x[i], INFINITY));
    if (i + 1 < x.size()) v.push_back(0.5 * (x[i] + x[i + 1]));
  }
  std::uniform_real_distribution<double> u(x.front() - 1.0, x.back() + 1.0);
  for (int k = 0; k < 20000; ++k) v.push_back(u(rng));
  return v;
}

void expect_identical_to_binary_search(const PiecewiseLinear& f, bool zero_outside, std::mt19937_64& rng) {
  const std::vector<double> x(f.x().begin(), f.x().end()), y(f.y().begin(), f.y().end());
  int mismatches = 0;
  for (double v : probe_points(x, rng))
    if (!same_bits(f.eval(v), reference_eval(x, y, zero_outside, v))) ++mismatches;
  EXPECT_EQ(mismatches, 0);
}

TEST(PiecewiseLinearLookup, SolarSpectrumAndCieFunctionsMatchBinarySearchBitForBit) {
  std::mt19937_64 rng(1);
  // AM0: 1-2 nm knots up to 2500 nm, then up to 600 000 nm apart.
  expect_identical_to_binary_search(am0_irradiance(), true, rng);
  const CieObserver& o = cie1931_observer();
  expect_identical_to_binary_search(o.xbar, true, rng);
  expect_identical_to_binary_search(o.ybar, true, rng);
  expect_identical_to_binary_search(o.zbar, true, rng);
}

TEST(PiecewiseLinearLookup, IrregularTablesMatchBinarySearchBitForBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int table = 0; table < 20; ++table) {
    // Dense runs with random gaps, steps spanning six decades, a few huge jumps.
    std::vector<double> x{-3.0}, y{u(rng)};
    const int n = 20 + static_cast<int>(u(rng) * 3000);
    for (int i = 1; i < n; ++i) {
      double step = std::pow(10.0, -3.0 + 6.0 * u(rng) * u(rng));
      if (u(rng) < 0.01) step *= 1e4;
      x.push_back(x.back() + step);
      y.push_back(u(rng) * 10.0 - 5.0);
    }
    const bool zero_outside = table % 2 == 0;
    const PiecewiseLinear f(x, y, zero_outside ? PiecewiseLinear::Outside::kZero : PiecewiseLinear::Outside::kClamp);
    expect_identical_to_binary_search(f, zero_outside, rng);
  }
}

TEST(PiecewiseLinearLookup, UniformGridWithKnotsOnBucketEdgesMatchesBinarySearch) {
  std::mt19937_64 rng(3);
  std::vector<double> x, y;
  for (int i = 0; i <= 470; ++i) {
    x.push_back(360.0 + i);
    y.push_back(std::sin(0.1 * i));
  }
  const PiecewiseLinear f(x, y, PiecewiseLinear::Outside::kZero);
  expect_identical_to_binary_search(f, true, rng);
  // Copies keep the index and agree too.
  const PiecewiseLinear g = f;
  EXPECT_TRUE(same_bits(g.eval(555.25), f.eval(555.25)));
  EXPECT_TRUE(same_bits(g.eval(555.25), reference_eval(x, y, true, 555.25)));
}

// cie1931_cmf locates the wavelength once (in ybar) for all three functions:
// each must still be, bit for bit, its own table's binary-search value.
TEST(PiecewiseLinearLookup, OneLocationServesEveryTableWithTheSameKnots) {
  std::mt19937_64 rng(11);
  const CieObserver& o = cie1931_observer();
  const std::vector<double> x(o.ybar.x().begin(), o.ybar.x().end());
  ASSERT_TRUE(std::equal(x.begin(), x.end(), o.xbar.x().begin(), o.xbar.x().end()));
  ASSERT_TRUE(std::equal(x.begin(), x.end(), o.zbar.x().begin(), o.zbar.x().end()));
  const std::vector<double> xs(o.xbar.y().begin(), o.xbar.y().end()), ys(o.ybar.y().begin(), o.ybar.y().end()),
      zs(o.zbar.y().begin(), o.zbar.y().end());
  int mismatches = 0;
  for (double v : probe_points(x, rng)) {
    const Xyz cmf = cie1931_cmf(v);
    if (!same_bits(cmf.x, reference_eval(x, xs, true, v))) ++mismatches;
    if (!same_bits(cmf.y, reference_eval(x, ys, true, v))) ++mismatches;
    if (!same_bits(cmf.z, reference_eval(x, zs, true, v))) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0);
  // A one-knot table and a clamped one read the same location kinds right.
  const PiecewiseLinear one = PiecewiseLinear::constant(2.0);
  EXPECT_EQ(one.eval_at(one.locate(-7.0)), 2.0);
  const PiecewiseLinear clamp({1.0, 2.0}, {10.0, 20.0});
  const PiecewiseLinear zero({1.0, 2.0}, {-1.0, -2.0}, PiecewiseLinear::Outside::kZero);
  for (double v : {0.5, 1.0, 1.25, 2.0, 3.0}) {
    EXPECT_TRUE(same_bits(clamp.eval_at(zero.locate(v)), clamp.eval(v))) << v;
    EXPECT_TRUE(same_bits(zero.eval_at(clamp.locate(v)), zero.eval(v))) << v;
  }
}

}  // namespace
}  // namespace skyfarm

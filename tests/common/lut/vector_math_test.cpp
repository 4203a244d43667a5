// exp as plain arithmetic (common/lut/vector_math.h) against the library's,
// and the same bits from a vectorised clone as from scalar code.
#include "common/lut/vector_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "common/lut/simd_clones.h"

namespace skyfarm {
namespace {

using lut::exp_inline;


TEST(LutVectorMath, ExpMatchesTheLibrary) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> wide(-708.0, 709.0), optical_depths(-60.0, 0.0);
  double worst = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const double x = k % 2 ? wide(rng) : optical_depths(rng);
    worst = std::max(worst, std::abs(exp_inline(x) - std::exp(x)) / std::exp(x));
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
  EXPECT_LT(worst, 3e-16);
  // Subnormal results round like the library's (to within one unit); below
  // -745.2 and at -inf they are 0.
  for (double x : {-709.0, -720.5, -740.0, -745.0})
    EXPECT_NEAR(exp_inline(x), std::exp(x), 2.0 * std::numeric_limits<double>::denorm_min()) << x;
  EXPECT_EQ(exp_inline(-746.0), 0.0);
  EXPECT_EQ(exp_inline(-1e300), 0.0);
  EXPECT_EQ(exp_inline(-std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(exp_inline(0.0), 1.0);
  EXPECT_EQ(exp_inline(-0.0), 1.0);
  EXPECT_TRUE(std::isnan(exp_inline(std::numeric_limits<double>::quiet_NaN())));
}

// The single-precision exp against the library's in double: relative error
// < 1.5e-7 (a float's half ulp is 6e-8; the reduction and the 7-term series
// add a few) over the transmittance table's range of -tau and beyond.
TEST(LutVectorMath, FloatExpMatchesTheLibrary) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<float> wide(-87.0f, 88.0f), optical_depths(-60.0f, 0.0f);
  double worst = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const float x = k % 2 ? wide(rng) : optical_depths(rng);
    const double ref = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::abs(lut::exp_inline_f(x) - ref) / ref);
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_relative_error", text);
  EXPECT_LT(worst, 1.5e-7);
  // Subnormal results to within a unit of the float they round to; 0 below
  // -103.9 and at -inf.
  for (float x : {-88.0f, -95.5f, -100.0f, -103.0f})
    EXPECT_NEAR(lut::exp_inline_f(x), std::exp(static_cast<double>(x)),
                2.0 * std::numeric_limits<float>::denorm_min()) << x;
  EXPECT_EQ(lut::exp_inline_f(-104.0f), 0.0f);
  EXPECT_EQ(lut::exp_inline_f(-1e30f), 0.0f);
  EXPECT_EQ(lut::exp_inline_f(-std::numeric_limits<float>::infinity()), 0.0f);
  EXPECT_EQ(lut::exp_inline_f(0.0f), 1.0f);
  EXPECT_TRUE(std::isnan(lut::exp_inline_f(std::numeric_limits<float>::quiet_NaN())));
}

// Loops the compiler vectorises in the AVX-512 / AVX2 clone on this machine,
// against the same functions called one value at a time from a function that
// is never cloned: the bits must agree (simd_clones.h).
SKYFARM_LUT_SIMD_CLONES
void exp_and_sqrt_of_all(const std::vector<double>& x, std::vector<double>& e, std::vector<double>& s,
                         std::vector<float>& e_f) {
  const std::size_t n = x.size();
  const double* in = x.data();
  double *__restrict out_e = e.data(), *__restrict out_s = s.data();
  float* __restrict out_f = e_f.data();
  for (std::size_t i = 0; i < n; ++i) {
    out_e[i] = exp_inline(-in[i]);
    out_s[i] = std::sqrt(in[i]);
  }
  for (std::size_t i = 0; i < n; ++i) out_f[i] = lut::exp_inline_f(static_cast<float>(-in[i]));
}

[[gnu::noinline]] double exp_one(double x) { return exp_inline(-x); }
[[gnu::noinline]] double sqrt_one(double x) { return std::sqrt(x); }
[[gnu::noinline]] float exp_one_f(double x) { return lut::exp_inline_f(static_cast<float>(-x)); }

TEST(LutVectorMath, VectorisedLoopsGiveTheScalarBits) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> U(0.0, 50.0);
  std::vector<double> x(1003), e(x.size()), s(x.size());
  std::vector<float> e_f(x.size());
  for (double& v : x) v = U(rng) * U(rng);
  exp_and_sqrt_of_all(x, e, s, e_f);
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(e[i], exp_one(x[i])) << x[i];
    EXPECT_EQ(e_f[i], exp_one_f(x[i])) << x[i];
    EXPECT_EQ(s[i], sqrt_one(x[i])) << x[i];
  }
}

}  // namespace
}  // namespace skyfarm

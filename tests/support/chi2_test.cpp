// Tests of the chi-square harness itself: it must pass right samplers and,
// above all, be able to FAIL wrong ones (a harness that always passes proves
// nothing).  Significance 0.01 throughout; a wrong sampler must reach p < 1e-6.
#include "tests/support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "common/atmosphere/phase_function.h"
#include "common/core/constants.h"
#include "common/sampling/warps.h"

namespace skyfarm::testing {
namespace {

constexpr double kAlpha = 0.01;

// Uniform double in [0, 1) from the top 53 bits (never 1, unlike some
// std::generate_canonical implementations).
double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

TEST(Chi2Harness, RegularizedGammaQMatchesReferenceValues) {
  // Reference values from mpmath.gammainc(a, x, inf, regularized=True), 30 digits.
  struct Case {
    double a, x, q;
  };
  const Case cases[] = {
      {0.5, 1.920729410347062, 0.050000000000000057},   // chi2(1) 95 % quantile
      {5.0, 11.604625579477178, 0.010000000000000014},  // chi2(10) 99 % quantile
      {50.0, 67.90335, 0.010000035680287005},
      {2.5, 0.1, 0.99911386121118756},
      {1.0, 30.0, 9.3576229688401746e-14},
      {100.0, 300.0, 1.4110215102111521e-41},
      {0.5, 1e-8, 0.99988716208366658},
      {3.0, 3.5, 0.32084719886213407},
  };
  for (const Case& c : cases) {
    EXPECT_NEAR(regularized_gamma_q(c.a, c.x) / c.q, 1.0, 1e-12) << "a = " << c.a << ", x = " << c.x;
  }
  EXPECT_EQ(regularized_gamma_q(2.0, 0.0), 1.0);
  EXPECT_EQ(regularized_gamma_q(2.0, std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_NEAR(chi2_survival(3.841458820694124, 1), 0.05, 1e-14);
}

TEST(Chi2Harness, SidakCorrection) {
  EXPECT_DOUBLE_EQ(sidak_significance(0.01, 1), 0.01);
  const double per_test = sidak_significance(0.01, 4);
  EXPECT_NEAR(1.0 - std::pow(1.0 - per_test, 4), 0.01, 1e-15);
}

// Exponential distribution on [0, 8] (truncated): right and wrong rates.
TEST(Chi2Harness, OneDimensionalPassesRightAndFailsWrongDensity) {
  std::mt19937_64 rng(11);
  const double x_max = 8.0, norm = -std::expm1(-x_max);
  std::vector<double> samples(200000);
  for (double& x : samples) x = -std::log1p(-uniform(rng) * norm);  // inverse CDF of the truncated exponential
  const auto right = [&](double x) { return std::exp(-x) / norm; };
  const double rate = 1.02, wrong_norm = -std::expm1(-rate * x_max) / rate;
  const auto wrong = [&](double x) { return std::exp(-rate * x) / wrong_norm; };
  const Chi2Result ok = chi2_test_1d(right, samples, 0.0, x_max, 64);
  EXPECT_GT(ok.p_value, kAlpha) << ok.detail;
  EXPECT_GT(ok.dof, 10);
  const Chi2Result bad = chi2_test_1d(wrong, samples, 0.0, x_max, 64);
  EXPECT_LT(bad.p_value, 1e-6) << bad.detail;
  EXPECT_NE(bad.detail.find("worst cells"), std::string::npos) << bad.detail;
}

// The brief's canonical wrong sampler: Henyey-Greenstein samples (g = 0.7)
// tested against g = 0.65 must fail, against g = 0.7 must pass; in 1-D (mu)
// and on the sphere.
TEST(Chi2Harness, HenyeyGreensteinAgainstDifferentGFails) {
  const PhaseFunction sampled = PhaseFunction::henyey_greenstein(0.7);
  const PhaseFunction other = PhaseFunction::henyey_greenstein(0.65);
  std::mt19937_64 rng(12);
  std::vector<double> mu(200000);
  std::vector<glm::dvec3> w(mu.size());
  for (std::size_t i = 0; i < mu.size(); ++i) {
    mu[i] = sampled.sample_cos_theta(uniform(rng));
    w[i] = sampled.sample_direction({0.0, 0.0, 1.0}, uniform(rng), uniform(rng));
  }
  const auto pdf_mu = [](const PhaseFunction& p) { return [&p](double m) { return 2.0 * kPi * p.eval(m); }; };
  const auto pdf_w = [](const PhaseFunction& p) { return [&p](const glm::dvec3& v) { return p.eval(v.z); }; };

  const Chi2Result ok_1d = chi2_test_1d(pdf_mu(sampled), mu, -1.0, 1.0, 100);
  EXPECT_GT(ok_1d.p_value, sidak_significance(kAlpha, 2)) << ok_1d.detail;
  const Chi2Result ok_sphere = chi2_test_sphere(pdf_w(sampled), w, 20, 40);
  EXPECT_GT(ok_sphere.p_value, sidak_significance(kAlpha, 2)) << ok_sphere.detail;

  const Chi2Result bad_1d = chi2_test_1d(pdf_mu(other), mu, -1.0, 1.0, 100);
  EXPECT_LT(bad_1d.p_value, 1e-6) << bad_1d.detail;
  const Chi2Result bad_sphere = chi2_test_sphere(pdf_w(other), w, 20, 40);
  EXPECT_LT(bad_sphere.p_value, 1e-6) << bad_sphere.detail;
}

// A sampler with a subtle azimuthal bias (phi density off by up to 5 %) must fail on the
// sphere although its cos(theta) distribution is right.
TEST(Chi2Harness, SphereDetectsAzimuthalBias) {
  std::mt19937_64 rng(13);
  std::vector<glm::dvec3> good(300000), bad(300000);
  for (std::size_t i = 0; i < good.size(); ++i) {
    const double u1 = uniform(rng), u2 = uniform(rng);
    good[i] = square_to_uniform_sphere({u1, u2});
    bad[i] = square_to_uniform_sphere({u1, 0.95 * u2 + 0.05 * u2 * u2});
  }
  const Chi2Result ok = chi2_test_sphere(square_to_uniform_sphere_pdf, good, 16, 32);
  EXPECT_GT(ok.p_value, kAlpha) << ok.detail;
  const Chi2Result fail = chi2_test_sphere(square_to_uniform_sphere_pdf, bad, 16, 32);
  EXPECT_LT(fail.p_value, 1e-6) << fail.detail;
}

TEST(Chi2Harness, PreChecksFail) {
  const auto uniform_pdf = [](double) { return 1.0; };
  // A sample outside the domain.
  Chi2Result r = chi2_test_1d(uniform_pdf, {0.5, 0.25, 1.5}, 0.0, 1.0, 4);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("outside the domain"), std::string::npos) << r.detail;
  // A NaN sample.
  r = chi2_test_1d(uniform_pdf, {0.5, std::nan("")}, 0.0, 1.0, 4);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("not finite"), std::string::npos) << r.detail;
  // A pdf that integrates to 2.
  std::vector<double> samples(1000);
  std::mt19937_64 rng(14);
  for (double& x : samples) x = uniform(rng);
  r = chi2_test_1d([](double) { return 2.0; }, samples, 0.0, 1.0, 10);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("integrates to"), std::string::npos) << r.detail;
  // A negative pdf.
  r = chi2_test_1d([](double x) { return 2.0 * x - 0.1; }, samples, 0.0, 1.0, 10);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("negative"), std::string::npos) << r.detail;
  // Samples where the pdf is zero: uniform [0,1) samples against a density on [0, 0.5].
  r = chi2_test_1d([](double x) { return x < 0.5 ? 2.0 : 0.0; }, samples, 0.0, 1.0, 10);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("expected count"), std::string::npos) << r.detail;
  // Sphere: a vector that is not unit length, and samples below a hemisphere pdf.
  r = chi2_test_sphere(square_to_uniform_sphere_pdf, {{0.0, 0.0, 1.0}, {0.0, 0.0, 2.0}}, 4, 4);
  EXPECT_EQ(r.p_value, 0.0);
  std::vector<glm::dvec3> sphere(20000);
  for (auto& w : sphere) w = square_to_uniform_sphere({uniform(rng), uniform(rng)});
  r = chi2_test_sphere(square_to_uniform_hemisphere_pdf, sphere, 8, 8);
  EXPECT_EQ(r.p_value, 0.0);
  EXPECT_NE(r.detail.find("expected count"), std::string::npos) << r.detail;
}

TEST(Chi2Harness, PoolsSparseCells) {
  // Few samples in many bins: most cells expect < 5 and must be pooled, and
  // the test still runs (dof >= 1) and passes.
  std::mt19937_64 rng(15);
  std::vector<double> samples(300);
  for (double& x : samples) x = uniform(rng);
  const Chi2Result r = chi2_test_1d([](double) { return 1.0; }, samples, 0.0, 1.0, 200);
  EXPECT_GE(r.dof, 1);
  EXPECT_GT(r.p_value, kAlpha) << r.detail;
  EXPECT_NE(r.detail.find("pooled"), std::string::npos) << r.detail;
}

}  // namespace
}  // namespace skyfarm::testing

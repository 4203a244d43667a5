// Tests of the square-to-sphere warps and the orthonormal frame
// (common/sampling/warps.h).
//
// Oracles: every pdf integrates to 1 over its domain (composite Gauss-Legendre
// in (cos theta, phi), split at the pdf's discontinuities); chi-square
// goodness-of-fit of the warped samples against the stated pdf
// (tests/support/chi2.h, significance 0.01 per warp, Sidak-corrected where a
// warp is tested in more than one view); closed-form identities (the cone's
// sin^2(theta/2) = u sin^2(theta_max/2), which must hold to 1e-12 for the
// 0.2666 deg sun disk); and orthonormality / handedness of the frame for
// random and axis-aligned normals, (0, 0, -1) included.
// Fixed seeds (std::mt19937_64).
#include "common/sampling/warps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <random>
#include <string>
#include <vector>

#include "common/core/constants.h"
#include "tests/support/chi2.h"

namespace skyfarm {
namespace {

using testing::chi2_test_1d;
using testing::chi2_test_sphere;
using testing::Chi2Result;
using testing::sidak_significance;

constexpr double kAlpha = 0.01;
constexpr int kSamples = 200000;
constexpr double kSunRadius = 0.2666 * kDegToRad;

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Edge-case points of the unit square, u in [0, 1).
const double kOneMinus = 1.0 - 0x1.0p-53;
const glm::dvec2 kEdgeUs[] = {{0.0, 0.0},     {kOneMinus, kOneMinus}, {0.0, kOneMinus},  {kOneMinus, 0.0}, {0.5, 0.5},
                              {1e-300, 0.25}, {0.25, 1e-300},         {0x1.0p-53, 0.75}, {0.5, 0.0},       {0.0, 0.5}};

// Integral of a pdf over the sphere: composite 8-point Gauss-Legendre in
// mu = cos(theta) with breaks (discontinuities of the pdf) and a periodic
// trapezoid rule in phi.
double integrate_sphere(const std::function<double(const glm::dvec3&)>& pdf, std::vector<double> breaks = {}) {
  static const double x8[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static const double w8[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  breaks.push_back(-1.0);
  breaks.push_back(1.0);
  std::sort(breaks.begin(), breaks.end());
  const int panels = 64, n_phi = 64;
  double sum = 0.0;
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double h = (breaks[b + 1] - breaks[b]) / panels;
    for (int p = 0; p < panels; ++p) {
      const double c = breaks[b] + (p + 0.5) * h, r = 0.5 * h;
      for (int j = 0; j < 8; ++j) {
        const double mu = c + (j < 4 ? -r * x8[j] : r * x8[j - 4]);
        const double weight = r * w8[j % 4];
        const double sin_theta = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
        for (int k = 0; k < n_phi; ++k) {
          const double phi = 2.0 * kPi * (k + 0.5) / n_phi;
          sum += weight * (2.0 * kPi / n_phi) * pdf({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu});
        }
      }
    }
  }
  return sum;
}

// Chi-square of a sphere warp; prints the p-value for the record.
void expect_sphere_chi2(const std::string& name, const std::function<glm::dvec3(const glm::dvec2&)>& warp,
                        const std::function<double(const glm::dvec3&)>& pdf, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<glm::dvec3> samples(kSamples);
  for (auto& w : samples) {
    const double u1 = uniform(rng), u2 = uniform(rng);
    w = warp({u1, u2});
    ASSERT_GT(pdf(w), 0.0) << name << ": a sample where the pdf is 0";
  }
  const Chi2Result r = chi2_test_sphere(pdf, samples, 20, 40);
  std::printf("[chi2] %-28s sphere p=%.3g (dof %d)\n", name.c_str(), r.p_value, r.dof);
  EXPECT_GT(r.p_value, kAlpha) << name << ": " << r.detail;
}

TEST(Warps, UniformSphere) {
  EXPECT_NEAR(integrate_sphere(square_to_uniform_sphere_pdf), 1.0, 1e-12);
  expect_sphere_chi2("uniform_sphere", square_to_uniform_sphere, square_to_uniform_sphere_pdf, 1);
  for (const glm::dvec2& u : kEdgeUs) EXPECT_NEAR(glm::length(square_to_uniform_sphere(u)), 1.0, 1e-15);
}

TEST(Warps, VonMisesFisher) {
  for (double kappa : {0.5, 10.0, 200.0}) {
    auto pdf = [kappa](const glm::dvec3& w) { return square_to_von_mises_fisher_pdf(w.z, kappa); };
    // Sharp lobes need the quadrature's panels near the pole.
    std::vector<double> breaks;
    for (double b : {1.0 - 10.0 / kappa, 1.0 - 1.0 / kappa})
      if (b > -1.0) breaks.push_back(b);
    EXPECT_NEAR(integrate_sphere(pdf, breaks), 1.0, 1e-6) << "kappa " << kappa;
    expect_sphere_chi2("von_mises_fisher k=" + std::to_string(kappa),
                       [kappa](const glm::dvec2& u) { return square_to_von_mises_fisher(u, kappa); }, pdf, 11);
    for (const glm::dvec2& u : kEdgeUs) EXPECT_NEAR(glm::length(square_to_von_mises_fisher(u, kappa)), 1.0, 1e-12);
  }
}

TEST(Warps, UniformHemisphere) {
  EXPECT_NEAR(integrate_sphere(square_to_uniform_hemisphere_pdf, {0.0}), 1.0, 1e-12);
  expect_sphere_chi2("uniform_hemisphere", square_to_uniform_hemisphere, square_to_uniform_hemisphere_pdf, 2);
  for (const glm::dvec2& u : kEdgeUs) {
    const glm::dvec3 w = square_to_uniform_hemisphere(u);
    EXPECT_NEAR(glm::length(w), 1.0, 1e-15);
    EXPECT_GT(w.z, 0.0);
  }
  EXPECT_EQ(square_to_uniform_hemisphere_pdf({0.0, 0.0, -1.0}), 0.0);
}

TEST(Warps, CosineHemisphere) {
  EXPECT_NEAR(integrate_sphere(square_to_cosine_hemisphere_pdf, {0.0}), 1.0, 1e-12);
  expect_sphere_chi2("cosine_hemisphere", square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf, 3);
  for (const glm::dvec2& u : kEdgeUs) {
    const glm::dvec3 w = square_to_cosine_hemisphere(u);
    EXPECT_NEAR(glm::length(w), 1.0, 1e-15);
    EXPECT_GE(w.z, 0.0);
  }
  EXPECT_EQ(square_to_cosine_hemisphere_pdf({0.0, 0.0, -1.0}), 0.0);
  EXPECT_NEAR(square_to_cosine_hemisphere_pdf({0.0, 0.0, 1.0}), kInvPi, 1e-16);
}

// The concentric map is area-preserving: r^2 and phi of its points are uniform.
TEST(Warps, ConcentricDisk) {
  std::mt19937_64 rng(4);
  std::vector<double> r2(kSamples), phi(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const glm::dvec2 p = square_to_concentric_disk({uniform(rng), uniform(rng)});
    r2[i] = p.x * p.x + p.y * p.y;
    phi[i] = std::atan2(p.y, p.x) + kPi;
    ASSERT_LE(r2[i], 1.0 + 1e-15);
  }
  const double alpha = sidak_significance(kAlpha, 2);
  const Chi2Result a = chi2_test_1d([](double) { return 1.0; }, r2, 0.0, 1.0 + 1e-15, 50);
  const Chi2Result b = chi2_test_1d([](double) { return 1.0 / (2.0 * kPi); }, phi, 0.0, 2.0 * kPi, 64);
  std::printf("[chi2] %-28s r^2 p=%.3g (dof %d)  phi p=%.3g (dof %d)\n", "concentric_disk", a.p_value, a.dof, b.p_value,
              b.dof);
  EXPECT_GT(a.p_value, alpha) << a.detail;
  EXPECT_GT(b.p_value, alpha) << b.detail;
  EXPECT_EQ(square_to_concentric_disk({0.5, 0.5}), glm::dvec2(0.0, 0.0));
  EXPECT_NEAR(square_to_concentric_disk_pdf({0.3, 0.3}), kInvPi, 1e-16);
  EXPECT_EQ(square_to_concentric_disk_pdf({0.9, 0.9}), 0.0);
}

TEST(Warps, UniformConeWide) {
  for (double theta_max : {0.5, 2.0}) {  // 28.6 deg, and 114.6 deg (past the equator)
    const auto warp = [theta_max](const glm::dvec2& u) { return square_to_uniform_cone(u, theta_max); };
    const auto pdf = [theta_max](const glm::dvec3& w) { return square_to_uniform_cone_pdf(w, theta_max); };
    EXPECT_NEAR(integrate_sphere(pdf, {std::cos(theta_max)}), 1.0, 1e-12) << theta_max;
    EXPECT_NEAR(uniform_cone_solid_angle(theta_max), 2.0 * kPi * (1.0 - std::cos(theta_max)), 1e-14);
    expect_sphere_chi2("uniform_cone(" + std::to_string(theta_max) + ")", warp, pdf, theta_max < 1.0 ? 5 : 6);
  }
  EXPECT_NEAR(uniform_cone_solid_angle(kPi), 4.0 * kPi, 1e-14);
  EXPECT_NEAR(glm::length(square_to_uniform_cone({kOneMinus, 0.3}, kPi)), 1.0, 1e-15);
}

// The sun disk: 0.2666 deg.  2 pi (1 - cos theta_max) in double loses ~5 of
// its 16 digits; the half-angle form must not.  Sampling: sin^2(theta/2)
// = u.x sin^2(theta_max/2) exactly (to rounding), and chi-square of the
// normalised sin^2(theta/2) and of phi, both uniform.
TEST(Warps, UniformConeSunDisk) {
  const double theta = kSunRadius;
  // Series 4 pi sin^2(x/2) = pi x^2 (1 - x^2/12 + x^4/360 - ...).
  const double series = kPi * theta * theta * (1.0 - theta * theta / 12.0 + std::pow(theta, 4) / 360.0);
  EXPECT_NEAR(uniform_cone_solid_angle(theta) / series, 1.0, 1e-14);
  EXPECT_NEAR(uniform_cone_solid_angle(theta), 6.80e-5, 1e-7);  // the sun's ~6.8e-5 sr
  const auto pdf = [theta](const glm::dvec3& w) { return square_to_uniform_cone_pdf(w, theta); };
  EXPECT_NEAR(integrate_sphere(pdf, {std::cos(theta)}), 1.0, 1e-9);

  const double half = std::sin(0.5 * theta);
  for (double u1 : {0.0, 1e-300, 1e-12, 0.01, 0.3, 0.5, 0.9, kOneMinus}) {
    const glm::dvec3 w = square_to_uniform_cone({u1, 0.37}, theta);
    EXPECT_NEAR(glm::length(w), 1.0, 1e-15);
    // sin^2(theta/2) = (x^2 + y^2) / (2 (1 + z)) for a unit vector: no cancellation.
    const double s2 = (w.x * w.x + w.y * w.y) / (2.0 * (1.0 + w.z));
    EXPECT_NEAR(s2, u1 * half * half, 1e-12 * half * half) << "u1 = " << u1;
    EXPECT_GT(pdf(w), 0.0) << "u1 = " << u1;
  }
  EXPECT_EQ(pdf(glm::normalize(glm::dvec3{std::sin(1.01 * theta), 0.0, std::cos(1.01 * theta)})), 0.0);
  EXPECT_GT(pdf(glm::normalize(glm::dvec3{std::sin(0.99 * theta), 0.0, std::cos(0.99 * theta)})), 0.0);

  std::mt19937_64 rng(7);
  std::vector<double> v(kSamples), phi(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const glm::dvec3 w = square_to_uniform_cone({uniform(rng), uniform(rng)}, theta);
    v[i] = (w.x * w.x + w.y * w.y) / (2.0 * (1.0 + w.z)) / (half * half);
    phi[i] = std::atan2(w.y, w.x) + kPi;
  }
  const double alpha = sidak_significance(kAlpha, 2);
  const Chi2Result a = chi2_test_1d([](double) { return 1.0; }, v, 0.0, 1.0 + 1e-12, 50);
  const Chi2Result b = chi2_test_1d([](double) { return 1.0 / (2.0 * kPi); }, phi, 0.0, 2.0 * kPi, 64);
  std::printf("[chi2] %-28s sin^2(theta/2) p=%.3g (dof %d)  phi p=%.3g (dof %d)\n", "uniform_cone(sun)", a.p_value,
              a.dof, b.p_value, b.dof);
  EXPECT_GT(a.p_value, alpha) << a.detail;
  EXPECT_GT(b.p_value, alpha) << b.detail;
}

void expect_orthonormal(const glm::dvec3& n) {
  const Frame f(n);
  const std::string where =
      "n = (" + std::to_string(n.x) + ", " + std::to_string(n.y) + ", " + std::to_string(n.z) + ")";
  EXPECT_NEAR(glm::length(f.s), 1.0, 1e-14) << where;
  EXPECT_NEAR(glm::length(f.t), 1.0, 1e-14) << where;
  EXPECT_NEAR(glm::dot(f.s, f.t), 0.0, 1e-14) << where;
  EXPECT_NEAR(glm::dot(f.s, n), 0.0, 1e-14) << where;
  EXPECT_NEAR(glm::dot(f.t, n), 0.0, 1e-14) << where;
  EXPECT_EQ(f.n, n);
  const glm::dvec3 c = glm::cross(f.s, f.t);  // right-handed
  EXPECT_NEAR(glm::length(c - n), 0.0, 1e-14) << where;
  const glm::dvec3 v{0.3, -0.7, 0.2};
  EXPECT_NEAR(glm::length(f.to_local(f.to_world(v)) - v), 0.0, 1e-14) << where;
  EXPECT_NEAR(glm::length(f.to_world(f.to_local(v)) - v), 0.0, 1e-14) << where;
  EXPECT_NEAR(glm::length(f.to_world({0.0, 0.0, 1.0}) - n), 0.0, 1e-15) << where;
}

TEST(WarpsFrame, OrthonormalForAxisAlignedNormals) {
  const glm::dvec3 axes[] = {{1.0, 0.0, 0.0}, {-1.0, 0.0, 0.0}, {0.0, 1.0, 0.0},   {0.0, -1.0, 0.0},
                             {0.0, 0.0, 1.0}, {0.0, 0.0, -1.0}, {-0.0, -0.0, -1.0}};
  for (const glm::dvec3& n : axes) expect_orthonormal(n);
  // Just off -z, where the original Frisvad (2012) basis breaks down.
  expect_orthonormal(glm::normalize(glm::dvec3{1e-8, 1e-8, -1.0}));
  expect_orthonormal(glm::normalize(glm::dvec3{-1e-12, 3e-12, -1.0}));
  expect_orthonormal(glm::normalize(glm::dvec3{1e-8, 0.0, 1.0}));
}

TEST(WarpsFrame, OrthonormalForRandomNormals) {
  std::mt19937_64 rng(8);
  for (int i = 0; i < 20000; ++i) expect_orthonormal(square_to_uniform_sphere({uniform(rng), uniform(rng)}));
}

TEST(WarpsFrame, DefaultIsIdentity) {
  const Frame f;
  const glm::dvec3 v{0.1, 0.2, 0.3};
  EXPECT_EQ(f.to_world(v), v);
  EXPECT_EQ(f.to_local(v), v);
}

}  // namespace
}  // namespace skyfarm

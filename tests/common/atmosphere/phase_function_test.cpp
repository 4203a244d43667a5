// Tests of the phase functions (common/atmosphere/phase_function.h).
//
// Oracles: the normalisation 2 pi int p dmu = 1 and the mean cosine by an
// independent graded Gauss-Legendre quadrature of eval(); the analytic mean
// cosines (HG: g; CS: 3g(4+g^2)/(5(2+g^2)); Rayleigh: 0; the water-cloud Mie
// table: 0.8643 from its source); the limits HG -> isotropic and
// CS -> Rayleigh (gamma = 0); exactness of sampling, F(sample(u)) = u with F
// integrated independently from eval(); and chi-square goodness-of-fit of the
// samples against eval() (tests/support/chi2.h) at significance 0.01 per case,
// Sidak-corrected over the 4 tests of a case: cos(theta) on a uniform grid,
// log(1 - mu + 1e-10) and log(1 + mu + 1e-10) (which resolve forward and
// backward peaks down to 1e-10 in 1 - |mu|), and the scattered directions on
// the sphere about the incident propagation direction.
// Fixed seeds (std::mt19937_64) make every run identical.
#include "common/atmosphere/phase_function.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/core/constants.h"
#include "common/data/csv_table.h"
#include "tests/support/chi2.h"

namespace skyfarm {
namespace {

using testing::chi2_test_1d;
using testing::chi2_test_sphere;
using testing::Chi2Result;
using testing::sidak_significance;

constexpr double kAlpha = 0.01;       // significance of one chi-square case
constexpr int kChi2Samples = 200000;  // per case
constexpr double kLogFloor = 1e-10;   // the log views resolve 1 - |mu| down to this

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// --- Independent quadrature: composite 8-point Gauss-Legendre on panels that
// are graded geometrically towards mu = -1 and mu = 1 (widths 2^-k), so that
// peaks of width 1e-6 at the ends are resolved, plus caller-given breaks
// (table knots), each panel split in two.
double integrate(const std::function<double(double)>& f, double a, double b,
                 const std::vector<double>& extra_breaks = {}) {
  static const double x8[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static const double w8[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  std::vector<double> breaks{a, b, 0.0};
  for (int k = 1; k <= 60; ++k) {
    breaks.push_back(1.0 - std::ldexp(1.0, -k));
    breaks.push_back(-1.0 + std::ldexp(1.0, -k));
  }
  breaks.insert(breaks.end(), extra_breaks.begin(), extra_breaks.end());
  std::vector<double> inside;
  for (double x : breaks) {
    if (x >= a && x <= b) inside.push_back(x);
  }
  std::sort(inside.begin(), inside.end());
  inside.erase(std::unique(inside.begin(), inside.end()), inside.end());
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < inside.size(); ++i) {
    for (int half = 0; half < 2; ++half) {
      const double lo = inside[i] + 0.5 * half * (inside[i + 1] - inside[i]);
      const double hi = half == 0 ? 0.5 * (inside[i] + inside[i + 1]) : inside[i + 1];
      const double c = 0.5 * (lo + hi), r = 0.5 * (hi - lo);
      for (int j = 0; j < 4; ++j) sum += r * w8[j] * (f(c - r * x8[j]) + f(c + r * x8[j]));
    }
  }
  return sum;
}

// --- The water-cloud Mie table (data/cloud_mie_phase_water_reff10um.csv).
struct MieTable {
  std::vector<double> angles_deg, p_4pi, p_per_sr, mu_knots;
};
const MieTable& mie_table() {
  static const MieTable table = [] {
    const CsvTable csv = CsvTable::embedded("cloud_mie_phase_water_reff10um.csv");
    MieTable t;
    t.angles_deg = csv.column("scattering_angle_deg");
    t.p_4pi = csv.column("phase_function_4pi_normalised");
    t.p_per_sr = csv.column("phase_function_per_sr");
    for (double a : t.angles_deg) t.mu_knots.push_back(std::cos(a * kDegToRad));
    return t;
  }();
  return table;
}
PhaseFunction mie_phase() { return PhaseFunction::tabulated(mie_table().angles_deg, mie_table().p_4pi); }

// A small table whose linear-in-mu interpolant the test builds itself.
const std::vector<double> kSmallAngles{0.0, 10.0, 45.0, 90.0, 135.0, 170.0, 180.0};
const std::vector<double> kSmallValues{50.0, 10.0, 2.0, 1.0, 0.5, 0.8, 1.0};

// The same interpolant, written independently: knots in mu, linear between.
double small_table_unnormalised(double mu) {
  const std::size_t n = kSmallAngles.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double mu_hi = std::cos(kSmallAngles[i] * kDegToRad), mu_lo = std::cos(kSmallAngles[i + 1] * kDegToRad);
    if (mu >= mu_lo && mu <= mu_hi) {
      const double x = (mu - mu_lo) / (mu_hi - mu_lo);
      return kSmallValues[i + 1] + x * (kSmallValues[i] - kSmallValues[i + 1]);
    }
  }
  return mu > 0.0 ? kSmallValues.front() : kSmallValues.back();
}
std::vector<double> small_table_mu_knots() {
  std::vector<double> mu;
  for (double a : kSmallAngles) mu.push_back(std::cos(a * kDegToRad));
  return mu;
}

struct Case {
  std::string name;
  PhaseFunction phase;
  double mean_cosine;  // the analytic / published value
  double mean_tolerance;
  std::vector<double> breaks;  // quadrature breaks (table knots)
};

double cs_mean_cosine(double g) { return 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g)); }

std::vector<Case> all_cases() {
  std::vector<Case> cases;
  for (double rho : {0.0, 0.0279, 1.0}) {
    cases.push_back({"rayleigh(" + std::to_string(rho) + ")", PhaseFunction::rayleigh(rho), 0.0, 1e-12, {}});
  }
  for (double g : {0.0, 1e-6, 0.7, -0.7, 0.99, -0.99, 0.999, -0.999}) {
    cases.push_back({"henyey_greenstein(" + std::to_string(g) + ")", PhaseFunction::henyey_greenstein(g), g, 1e-9, {}});
  }
  for (double g : {0.0, 1e-6, 0.7, -0.5, 0.99, -0.99}) {
    cases.push_back(
        {"cornette_shanks(" + std::to_string(g) + ")", PhaseFunction::cornette_shanks(g), cs_mean_cosine(g), 1e-9, {}});
  }
  // Linear in mu from 0 at 180 deg to 2 at 0 deg: p = (1 + mu)/(4 pi) exactly, <mu> = 1/3.
  cases.push_back({"table(linear)",
                   PhaseFunction::tabulated(std::vector<double>{0.0, 90.0, 180.0}, std::vector<double>{2.0, 1.0, 0.0}),
                   1.0 / 3.0,
                   1e-12,
                   {0.0}});
  cases.push_back({"table(small)", PhaseFunction::tabulated(kSmallAngles, kSmallValues), std::nan(""), 0.0,
                   small_table_mu_knots()});
  cases.push_back({"table(mie water cloud)", mie_phase(), 0.8643, 2e-3, mie_table().mu_knots});
  return cases;
}

TEST(PhaseFunction, NormalisedOverTheSphere) {
  for (const Case& c : all_cases()) {
    const double integral = integrate([&](double mu) { return 2.0 * kPi * c.phase.eval(mu); }, -1.0, 1.0, c.breaks);
    EXPECT_NEAR(integral, 1.0, 1e-4) << c.name;
    EXPECT_NEAR(integral, 1.0, 1e-9) << c.name << " (our own quadrature is far better than the 1e-4 asked)";
  }
}

TEST(PhaseFunction, MeanCosine) {
  for (const Case& c : all_cases()) {
    const double numeric = integrate([&](double mu) { return 2.0 * kPi * mu * c.phase.eval(mu); }, -1.0, 1.0, c.breaks);
    EXPECT_NEAR(c.phase.mean_cosine(), numeric, 1e-9) << c.name << ": mean_cosine() vs quadrature";
    if (!std::isnan(c.mean_cosine)) {
      EXPECT_NEAR(numeric, c.mean_cosine, std::max(c.mean_tolerance, 1e-9)) << c.name;
    }
  }
}

TEST(PhaseFunction, FiniteAndNonNegativeForEveryCosine) {
  std::vector<double> mus{-1.0, std::nextafter(-1.0, 0.0), -0.5, -1e-300, 0.0, 1e-300,
                          0.5,  std::nextafter(1.0, 0.0),  1.0};
  for (int i = 0; i <= 2000; ++i) mus.push_back(-1.0 + i * 1e-3);
  std::vector<Case> cases = all_cases();
  cases.push_back({"cornette_shanks(0.999)", PhaseFunction::cornette_shanks(0.999), 0, 0, {}});
  cases.push_back({"cornette_shanks(-0.999)", PhaseFunction::cornette_shanks(-0.999), 0, 0, {}});
  for (const Case& c : cases) {
    for (double mu : mus) {
      const double p = c.phase.eval(mu);
      EXPECT_TRUE(std::isfinite(p) && p >= 0.0) << c.name << " at mu = " << mu << ": " << p;
    }
  }
}

TEST(PhaseFunction, SampledCosineStaysInRange) {
  const double us[] = {0.0, 0x1.0p-1074, 1e-300, 1e-17, 0x1.0p-53, 0.25, 0.5, 0.75, 1.0 - 0x1.0p-53, 1.0};
  std::vector<Case> cases = all_cases();
  cases.push_back({"cornette_shanks(0.999)", PhaseFunction::cornette_shanks(0.999), 0, 0, {}});
  cases.push_back({"cornette_shanks(-0.999)", PhaseFunction::cornette_shanks(-0.999), 0, 0, {}});
  for (const Case& c : cases) {
    double previous = -2.0;
    for (double u : us) {
      const double mu = c.phase.sample_cos_theta(u);
      EXPECT_TRUE(mu >= -1.0 && mu <= 1.0) << c.name << " at u = " << u << ": " << mu;
      EXPECT_GE(mu, previous - 4e-16) << c.name << ": sample_cos_theta must be monotone in u (u = " << u << ")";
      previous = mu;
    }
  }
}

// Exact sampling: the CDF of eval() at sample_cos_theta(u) is u.
TEST(PhaseFunction, SamplingInvertsTheCdfOfEval) {
  const double us[] = {1e-9, 1e-5, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.9999, 1.0 - 1e-7};
  for (const Case& c : all_cases()) {
    for (double u : us) {
      const double mu = c.phase.sample_cos_theta(u);
      const double cdf = integrate([&](double m) { return 2.0 * kPi * c.phase.eval(m); }, -1.0, mu, c.breaks);
      EXPECT_NEAR(cdf, u, 1e-10 + 1e-9 * u) << c.name << " at u = " << u << " (mu = " << mu << ")";
    }
  }
}

TEST(PhaseFunction, CornetteShanksClosedFormCdf) {
  for (double g : {-0.999, -0.99, -0.5, -1e-7, 0.0, 1e-9, 1e-4, 0.3, 0.7, 0.99, 0.999}) {
    const CornetteShanksPhase cs{g};
    for (double mu : {-1.0, -0.9999, -0.5, 0.0, 0.3, 0.9, 0.99, 0.9999, 0.999999, 1.0}) {
      const double reference = integrate([&](double m) { return 2.0 * kPi * cs.eval(m); }, -1.0, mu);
      EXPECT_NEAR(cs.cdf(mu), reference, 1e-13 + 1e-11 * reference) << "g = " << g << ", mu = " << mu;
    }
    EXPECT_EQ(cs.cdf(-1.0), 0.0);
    EXPECT_NEAR(cs.cdf(1.0), 1.0, 1e-15) << "g = " << g;
  }
}

TEST(PhaseFunction, HenyeyGreensteinTendsToIsotropic) {
  const PhaseFunction hg0 = PhaseFunction::henyey_greenstein(0.0);
  for (double mu = -1.0; mu <= 1.0; mu += 0.125) EXPECT_DOUBLE_EQ(hg0.eval(mu), kInv4Pi);
  for (double u = 0.0; u < 1.0; u += 1.0 / 64.0) EXPECT_NEAR(hg0.sample_cos_theta(u), 2.0 * u - 1.0, 1e-15);
  for (double g : {1e-4, -1e-6, 1e-9}) {
    const PhaseFunction hg = PhaseFunction::henyey_greenstein(g);
    // p = (1 + 3 g mu + O(g^2)) / (4 pi), samples mu = 2u - 1 + O(g).
    for (double mu = -1.0; mu <= 1.0; mu += 0.125) {
      EXPECT_NEAR(hg.eval(mu) / kInv4Pi, 1.0 + 3.0 * g * mu, 10.0 * g * g + 1e-15) << "g = " << g;
    }
    for (double u = 0.0; u < 1.0; u += 1.0 / 64.0) {
      EXPECT_NEAR(hg.sample_cos_theta(u), 2.0 * u - 1.0, 2.0 * std::abs(g) + 1e-15) << "g = " << g;
    }
  }
}

TEST(PhaseFunction, CornetteShanksTendsToRayleigh) {
  const RayleighPhase rayleigh{0.0, 0.0};
  for (double g : {0.0, 1e-12, 1e-6, -1e-4}) {
    const PhaseFunction cs = PhaseFunction::cornette_shanks(g);
    for (double mu = -1.0; mu <= 1.0; mu += 0.125) {
      EXPECT_NEAR(cs.eval(mu) / rayleigh.eval(mu), 1.0, 4.0 * std::abs(g) + 1e-15) << "g = " << g << ", mu = " << mu;
    }
    for (double u = 0.0; u < 1.0; u += 1.0 / 64.0) {
      EXPECT_NEAR(cs.sample_cos_theta(u), rayleigh.sample_cos_theta(u), 4.0 * std::abs(g) + 1e-12)
          << "g = " << g << ", u = " << u;
    }
  }
}

// Bucholtz (1995) eq. 12-13 written out independently:
// P(Theta) = 3/(4(1 + 2 gamma)) [(1 + 3 gamma) + (1 - gamma) cos^2 Theta], normalised to 4 pi.
TEST(PhaseFunction, RayleighValues) {
  const PhaseFunction r0 = PhaseFunction::rayleigh(0.0);
  EXPECT_NEAR(r0.eval(0.0), 3.0 / (16.0 * kPi), 1e-16);
  EXPECT_NEAR(r0.eval(1.0), 6.0 / (16.0 * kPi), 1e-16);
  EXPECT_NEAR(r0.eval(-1.0), 6.0 / (16.0 * kPi), 1e-16);
  const double rho = 0.0279, gamma = rho / (2.0 - rho);
  const PhaseFunction r = PhaseFunction::rayleigh(rho);
  for (double mu : {-1.0, -0.3, 0.0, 0.6, 1.0}) {
    const double P = 3.0 / (4.0 * (1.0 + 2.0 * gamma)) * ((1.0 + 3.0 * gamma) + (1.0 - gamma) * mu * mu);
    EXPECT_NEAR(r.eval(mu), P / (4.0 * kPi), 1e-15);
  }
  // rho_n = 1 is isotropic.
  EXPECT_NEAR(PhaseFunction::rayleigh(1.0).eval(0.3), kInv4Pi, 1e-16);
}

TEST(PhaseFunction, TabulatedIsLinearInCosine) {
  const PhaseFunction t = PhaseFunction::tabulated(kSmallAngles, kSmallValues);
  const double norm =
      integrate([](double mu) { return 2.0 * kPi * small_table_unnormalised(mu); }, -1.0, 1.0, small_table_mu_knots());
  for (double mu = -1.0; mu <= 1.0; mu += 1.0 / 128.0) {
    EXPECT_NEAR(t.eval(mu), small_table_unnormalised(mu) / norm, 1e-12) << "mu = " << mu;
  }
  for (std::size_t i = 0; i < kSmallAngles.size(); ++i) {
    EXPECT_NEAR(t.eval(std::cos(kSmallAngles[i] * kDegToRad)), kSmallValues[i] / norm, 1e-12);
  }
  // Values outside [-1, 1] are clamped to the ends.
  EXPECT_EQ(t.eval(1.5), t.eval(1.0));
  EXPECT_EQ(t.eval(-1.5), t.eval(-1.0));
}

TEST(PhaseFunction, MieCloudTable) {
  const MieTable& table = mie_table();
  ASSERT_EQ(table.angles_deg.size(), 801u);
  const PhaseFunction mie = mie_phase();
  EXPECT_NEAR(mie.eval(1.0) * 4.0 * kPi / 7582.0, 1.0, 5e-3);  // P(0 deg), 4 pi-normalised, from the data README
  EXPECT_NEAR(mie.mean_cosine(), 0.8643, 2e-3);
  // At the knots the normalised interpolant matches the file's per-sr column
  // (which integrates to 1.000004 with the source's own quadrature).
  for (std::size_t i = 0; i < table.angles_deg.size(); i += 7) {
    EXPECT_NEAR(mie.eval(table.mu_knots[i]) / table.p_per_sr[i], 1.0, 2e-3) << table.angles_deg[i] << " deg";
  }
}

void expect_invalid(const std::vector<double>& angles, const std::vector<double>& values, const std::string& needle) {
  try {
    PhaseFunction::tabulated(angles, values);
    ADD_FAILURE() << "expected std::invalid_argument mentioning '" << needle << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(PhaseFunction, TabulatedRejectsBadTables) {
  expect_invalid({0.0, 90.0}, {1.0, 1.0, 1.0}, "same length");
  expect_invalid({0.0}, {1.0}, "at least 2");
  expect_invalid({1.0, 90.0, 180.0}, {1.0, 1.0, 1.0}, "start at 0");
  expect_invalid({0.0, 90.0, 179.0}, {1.0, 1.0, 1.0}, "end at 180");
  expect_invalid({0.0, 90.0, 90.0, 180.0}, {1.0, 1.0, 1.0, 1.0}, "strictly increasing");
  expect_invalid({0.0, 100.0, 90.0, 180.0}, {1.0, 1.0, 1.0, 1.0}, "strictly increasing");
  expect_invalid({0.0, 90.0, 180.0}, {1.0, -0.5, 1.0}, "values[1] is negative");
  expect_invalid({0.0, 90.0, 180.0}, {1.0, std::nan(""), 1.0}, "values[1] is not finite");
  expect_invalid({0.0, 90.0, 180.0}, {1.0, std::numeric_limits<double>::infinity(), 1.0}, "not finite");
  expect_invalid({0.0, std::nan(""), 180.0}, {1.0, 1.0, 1.0}, "angles_deg[1] is not finite");
  expect_invalid({0.0, 90.0, 180.0}, {0.0, 0.0, 0.0}, "all values are zero");
  expect_invalid({0.0, 1e-12, 180.0}, {1.0, 1.0, 1.0}, "too close");
}

TEST(PhaseFunction, RejectsBadParameters) {
  for (double g : {1.0, -1.0, 1.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(PhaseFunction::henyey_greenstein(g), std::invalid_argument) << g;
    EXPECT_THROW(PhaseFunction::cornette_shanks(g), std::invalid_argument) << g;
  }
  for (double rho : {-0.1, 1.1, std::nan("")}) EXPECT_THROW(PhaseFunction::rayleigh(rho), std::invalid_argument);
}

TEST(PhaseFunction, FromSpec) {
  EXPECT_EQ(PhaseFunction::from_spec(RayleighPhaseSpec{0.0279}).name(), "rayleigh");
  EXPECT_DOUBLE_EQ(PhaseFunction::from_spec(RayleighPhaseSpec{0.0279}).eval(0.2),
                   PhaseFunction::rayleigh(0.0279).eval(0.2));
  const PhaseFunction hg = PhaseFunction::from_spec(HenyeyGreensteinPhaseSpec{0.7});
  EXPECT_EQ(hg.name(), "henyey_greenstein");
  EXPECT_DOUBLE_EQ(hg.mean_cosine(), 0.7);
  const PhaseFunction cs = PhaseFunction::from_spec(CornetteShanksPhaseSpec{0.8});
  EXPECT_EQ(cs.name(), "cornette_shanks");
  EXPECT_DOUBLE_EQ(cs.eval(0.3), PhaseFunction::cornette_shanks(0.8).eval(0.3));
  const PhaseFunction table = PhaseFunction::from_spec(TablePhaseSpec{{0.0, 90.0, 180.0}, {2.0, 1.0, 0.0}});
  EXPECT_EQ(table.name(), "table");
  EXPECT_NEAR(table.eval(0.5), 1.5 / (4.0 * kPi), 1e-15);
  EXPECT_THROW(PhaseFunction::from_spec(TablePhaseSpec{{0.0, 90.0}, {1.0, 1.0}}), std::invalid_argument);
  EXPECT_THROW(PhaseFunction::from_spec(HenyeyGreensteinPhaseSpec{1.0}), std::invalid_argument);
  EXPECT_EQ(PhaseFunction().name(), "henyey_greenstein");
  EXPECT_DOUBLE_EQ(PhaseFunction().eval(0.4), kInv4Pi);
}

// The scattered direction makes the sampled angle with the propagation
// direction, and u2 turns it about that axis.
TEST(PhaseFunction, SampleDirectionAboutPropagation) {
  const PhaseFunction hg = PhaseFunction::henyey_greenstein(0.6);
  const glm::dvec3 axes[] = {{0.0, 0.0, 1.0},
                             {0.0, 0.0, -1.0},
                             {1.0, 0.0, 0.0},
                             glm::normalize(glm::dvec3{0.3, -0.5, 0.8}),
                             glm::normalize(glm::dvec3{1e-9, 0.0, -1.0})};
  for (const glm::dvec3& wo : axes) {
    for (double u1 : {0.0, 0.1, 0.5, 0.9, 1.0 - 0x1.0p-53}) {
      const glm::dvec3 a = hg.sample_direction(wo, u1, 0.0);
      const glm::dvec3 b = hg.sample_direction(wo, u1, 0.25);
      EXPECT_NEAR(glm::length(a), 1.0, 1e-14);
      EXPECT_NEAR(glm::dot(wo, a), hg.sample_cos_theta(u1), 1e-14);
      EXPECT_NEAR(glm::dot(wo, b), hg.sample_cos_theta(u1), 1e-14);
      // A quarter turn: the components perpendicular to wo are orthogonal.
      const glm::dvec3 pa = a - wo * glm::dot(wo, a), pb = b - wo * glm::dot(wo, b);
      EXPECT_NEAR(glm::dot(pa, pb), 0.0, 1e-14);
      EXPECT_NEAR(glm::dot(glm::cross(pa, pb), wo), glm::dot(pa, pa), 1e-14);  // counter-clockwise about wo
    }
  }
}

// --- Chi-square goodness of fit.

// A frame about n built by Gram-Schmidt (independent of warps.h's Frame).
glm::dvec3 to_frame_of(const glm::dvec3& n, const glm::dvec3& v) {
  const glm::dvec3 a = std::abs(n.x) < 0.9 ? glm::dvec3{1.0, 0.0, 0.0} : glm::dvec3{0.0, 1.0, 0.0};
  const glm::dvec3 s = glm::normalize(a - n * glm::dot(n, a));
  const glm::dvec3 t = glm::cross(n, s);
  return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)};
}

void expect_chi2(const std::string& name, const PhaseFunction& phase, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const glm::dvec3 wo = glm::normalize(glm::dvec3{0.3, -0.5, 0.8});
  std::vector<double> mu(kChi2Samples), forward(kChi2Samples), backward(kChi2Samples);
  std::vector<glm::dvec3> w(kChi2Samples);
  for (int i = 0; i < kChi2Samples; ++i) {
    mu[i] = phase.sample_cos_theta(uniform(rng));
    forward[i] = std::log((1.0 - mu[i]) + kLogFloor);
    backward[i] = std::log((1.0 + mu[i]) + kLogFloor);
    const double u1 = uniform(rng), u2 = uniform(rng);
    w[i] = to_frame_of(wo, phase.sample_direction(wo, u1, u2));
  }
  const auto pdf_mu = [&](double m) { return 2.0 * kPi * phase.eval(m); };
  // y = log(1 -+ mu + eps): pdf_y(y) = pdf_mu(mu(y)) e^y.
  const auto pdf_forward = [&](double y) { return pdf_mu(1.0 + kLogFloor - std::exp(y)) * std::exp(y); };
  const auto pdf_backward = [&](double y) { return pdf_mu(std::exp(y) - 1.0 - kLogFloor) * std::exp(y); };
  const double y0 = std::log(kLogFloor), y1 = std::log(2.0 + kLogFloor);

  const double alpha = sidak_significance(kAlpha, 4);
  const Chi2Result results[] = {
      chi2_test_1d(pdf_mu, mu, -1.0, 1.0, 100),
      chi2_test_1d(pdf_forward, forward, y0, y1, 100),
      chi2_test_1d(pdf_backward, backward, y0, y1, 100),
      chi2_test_sphere([&](const glm::dvec3& v) { return phase.eval(v.z); }, w, 20, 40),
  };
  const char* views[] = {"cos_theta", "log(1-mu)", "log(1+mu)", "sphere"};
  std::printf("[chi2] %-28s", name.c_str());
  for (int k = 0; k < 4; ++k) {
    std::printf("  %s p=%.3g (dof %d)", views[k], results[k].p_value, results[k].dof);
    EXPECT_GT(results[k].p_value, alpha) << name << ", " << views[k] << ": " << results[k].detail;
  }
  std::printf("\n");
}

TEST(PhaseFunctionChi2, Rayleigh) {
  expect_chi2("rayleigh(0)", PhaseFunction::rayleigh(0.0), 101);
  expect_chi2("rayleigh(0.0279)", PhaseFunction::rayleigh(0.0279), 102);
}

TEST(PhaseFunctionChi2, HenyeyGreenstein) {
  expect_chi2("henyey_greenstein(0)", PhaseFunction::henyey_greenstein(0.0), 201);
  expect_chi2("henyey_greenstein(0.7)", PhaseFunction::henyey_greenstein(0.7), 202);
  expect_chi2("henyey_greenstein(-0.7)", PhaseFunction::henyey_greenstein(-0.7), 203);
  expect_chi2("henyey_greenstein(0.99)", PhaseFunction::henyey_greenstein(0.99), 204);
  expect_chi2("henyey_greenstein(-0.99)", PhaseFunction::henyey_greenstein(-0.99), 205);
}

TEST(PhaseFunctionChi2, CornetteShanks) {
  expect_chi2("cornette_shanks(0.7)", PhaseFunction::cornette_shanks(0.7), 301);
  expect_chi2("cornette_shanks(-0.5)", PhaseFunction::cornette_shanks(-0.5), 302);
  expect_chi2("cornette_shanks(0.99)", PhaseFunction::cornette_shanks(0.99), 303);
}

TEST(PhaseFunctionChi2, Tabulated) {
  expect_chi2("table(small)", PhaseFunction::tabulated(kSmallAngles, kSmallValues), 401);
  expect_chi2("table(mie water cloud)", mie_phase(), 402);
}

}  // namespace
}  // namespace skyfarm

// The multiple-bounce models against an explicit simulation on a generated
// Beckmann heightfield (microsurface_heightfield.h, heightfield_random_walk.h),
// for the cases of Wang et al. 2022's supplement Figs. 4-8: rough diffuse
// (albedo 1) alpha 0.25, 0.5, 1.0, anisotropic diffuse 1.0 x 0.1 and the
// mirror conductor alpha 0.25.  Three estimates of the same lobes:
//   position-free  PositionFreeWalk, Beckmann, height-correlated (the default)
//   Heitz          Heitz et al. 2016's walk with heights (heitz_random_walk.h)
//   heightfield    rays traced on the surface itself
// E_r below is the supplement's quantity: the energy a lobe reflects, i.e.
// the fraction of the incident energy leaving after that many bounces (the
// facets do not absorb, so the orders sum to 1).  The test checks
//   - the surface: its triangles' slopes are Beckmann of the target alpha;
//   - E_r of the bounces >= 2 and the shape of their lobe (binned, L1 of the
//     two lobes each normalised to 1) of the position-free walk against the
//     heightfield, with tolerances stated at each case.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/material/microfacet_distribution.h"
#include "common/material/position_free_walk.h"
#include "tests/common/material/heightfield_random_walk.h"
#include "tests/common/material/heitz_random_walk.h"
#include "tests/common/material/lobe_distance.h"
#include "tests/common/material/microsurface_heightfield.h"

namespace skyfarm::material {
namespace {

using testing::bin_of;
using testing::kBins;
using testing::kPhiBins;
using testing::kThetaBins;
using testing::l1_distance;

constexpr double kPi = 3.14159265358979323846;
constexpr int kOrders = 4;  // E_r of orders 1, 2, 3 and >= 4

// The surface every comparison runs on: 512^2 samples, correlation length 8
// cells, so one period holds (512 / 8)^2 = 4096 independent patches.
constexpr int kSize = 512;
constexpr double kCorrelation = 8.0;

struct Lobe {
  std::array<double, kOrders> energy{};                            // E_r per order, fraction of the walks
  std::vector<double> multiple = std::vector<double>(kBins, 0.0);  // counts, orders >= 2
  int walks = 0;
  int lost = 0;
  double multiple_energy() const { return energy[1] + energy[2] + energy[3]; }
  // The standard error of multiple_energy() (a binomial fraction).
  double multiple_sigma() const {
    const double e = multiple_energy();
    return std::sqrt(e * (1.0 - e) / walks);
  }
};

// Runs `walks` walks of `trace` (returning nullopt or a direction and a
// bounce count) and tallies them.
template <class Trace>
Lobe tally(Trace trace, int walks) {
  Lobe lobe;
  lobe.walks = walks;
  for (int k = 0; k < walks; ++k) {
    int order = 0;
    glm::dvec3 w;
    if (!trace(&w, &order)) {
      ++lobe.lost;
      continue;
    }
    const int b = bin_of(w);
    if (b < 0 || order < 1) {
      ++lobe.lost;
      continue;
    }
    lobe.energy[std::min(order, kOrders) - 1] += 1.0 / walks;
    if (order >= 2) lobe.multiple[b] += 1.0;
  }
  return lobe;
}


// What two lobes drawn from the SAME distribution would show as L1 distance,
// from the counts alone: each normalised bin is off by a normal error of
// variance p_k / n, and E|N(0, s^2)| = s sqrt(2 / pi).
double l1_noise_floor(const std::vector<double>& a, const std::vector<double>& b) {
  double sa = 0.0;
  double sb = 0.0;
  for (int k = 0; k < kBins; ++k) {
    sa += a[k];
    sb += b[k];
  }
  double floor = 0.0;
  for (int k = 0; k < kBins; ++k) {
    const double p = (a[k] + b[k]) / (sa + sb);
    floor += std::sqrt(2.0 / kPi) * std::sqrt(p / sa + p / sb);
  }
  return floor;
}

struct Case {
  std::string name;
  double alpha_x;
  double alpha_y;
  bool diffuse;
};

struct Comparison {
  Lobe position_free;
  Lobe uncorrelated;  // the position-free walk without height correlation (the long table only)
  Lobe heitz;
  Lobe heightfield;
  int below = 0;
};

Comparison compare(const Case& c, double theta, int walks, std::uint64_t seed, bool with_heitz,
                   bool with_uncorrelated = false) {
  const MicrofacetDistribution dist(MicrofacetModel::beckmann, c.alpha_x, c.alpha_y);
  const glm::dvec3 wi(std::sin(theta), 0.0, std::cos(theta));
  Comparison out;
  {
    const PositionFreeWalk walk(dist, c.diffuse ? Facet::diffuse(1.0) : Facet::conductor(ConductorFresnel::mirror()),
                                HeightCorrelation::correlated);
    RandomSequence rng(seed * 3 + 1);
    out.position_free = tally(
        [&](glm::dvec3* w, int* order) {
          const auto exit = walk.trace(wi, rng);
          if (!exit) return false;
          *w = exit->direction;
          *order = exit->bounces;
          return true;
        },
        walks);
  }
  if (with_uncorrelated) {
    const PositionFreeWalk walk(dist, c.diffuse ? Facet::diffuse(1.0) : Facet::conductor(ConductorFresnel::mirror()),
                                HeightCorrelation::uncorrelated);
    RandomSequence rng(seed * 3 + 1);
    out.uncorrelated = tally(
        [&](glm::dvec3* w, int* order) {
          const auto exit = walk.trace(wi, rng);
          if (!exit) return false;
          *w = exit->direction;
          *order = exit->bounces;
          return true;
        },
        walks);
  }
  if (with_heitz) {
    const test::HeitzRandomWalk walk(dist, c.diffuse);
    RandomSequence rng(seed * 3 + 2);
    out.heitz = tally(
        [&](glm::dvec3* w, int* order) {
          const auto exit = walk.trace(wi, rng);
          if (!exit) return false;
          *w = exit->direction;
          *order = exit->order;
          return true;
        },
        walks);
  }
  {
    const test::MicrosurfaceHeightfield surface(c.alpha_x, c.alpha_y, kSize, kCorrelation, seed);
    test::HeightfieldRandomWalk walk(surface, c.diffuse);
    RandomSequence rng(seed * 3 + 3);
    out.heightfield = tally(
        [&](glm::dvec3* w, int* order) {
          const auto exit = walk.trace(wi, rng);
          if (!exit) return false;
          *w = exit->direction;
          *order = exit->order;
          return true;
        },
        walks);
    out.below = walk.below_count();
  }
  return out;
}

void print(const Case& c, double theta, const Comparison& r, bool with_heitz, bool with_uncorrelated = false) {
  auto row = [](const char* who, const Lobe& l) {
    std::printf("    %-14s E_r by order %.4f %.4f %.4f %.4f | bounces>=2 %.4f +- %.4f | lost %d\n", who, l.energy[0],
                l.energy[1], l.energy[2], l.energy[3], l.multiple_energy(), l.multiple_sigma(), l.lost);
  };
  std::printf("%s theta %.1f\n", c.name.c_str(), theta);
  row("position-free", r.position_free);
  if (with_uncorrelated) row("uncorrelated", r.uncorrelated);
  if (with_heitz) row("Heitz", r.heitz);
  row("heightfield", r.heightfield);
  auto pair = [](const char* name, const Lobe& a, const Lobe& b) {
    std::printf("  L1(%s) %.3f (noise %.3f)", name, l1_distance(a.multiple, b.multiple),
                l1_noise_floor(a.multiple, b.multiple));
  };
  std::printf("  ");
  pair("pf, hf", r.position_free, r.heightfield);
  if (with_heitz) {
    pair("Heitz, hf", r.heitz, r.heightfield);
    pair("pf, Heitz", r.position_free, r.heitz);
  }
  if (with_uncorrelated) {
    pair("uncorr, hf", r.uncorrelated, r.heightfield);
  }
  std::printf("  below %d\n", r.below);
}

// The generated surface: its triangles' slopes (p, q) are Beckmann of the
// target roughness, P22(p, q) = exp(-p^2 / ax^2 - q^2 / ay^2) / (pi ax ay).
//   - mean square slope alpha^2 / 2 per axis: exact by construction (the
//     cell sizes are set from it), so only a rounding tolerance;
//   - shape: with X = p / ax, Y = q / ay, X^2 + Y^2 is exponential of mean 1
//     and X sqrt(2) standard normal; the Kolmogorov distance of the
//     triangles' empirical distribution from those.  Measured 0.002-0.005 on
//     correct surfaces (one surface holds ~4096 independent patches, and
//     the triangles within a patch are not all alike); bound 0.02.  A
//     surface of too few waves, or slopes taken from the wrong neighbours,
//     is far outside;
//   - no correlation between p and q (the axes are the roughness axes):
//     |rho| < 0.05 (measured below 0.015).
void check_slopes(double alpha_x, double alpha_y, std::uint64_t seed) {
  const test::MicrosurfaceHeightfield surface(alpha_x, alpha_y, kSize, kCorrelation, seed);
  std::vector<double> radial;
  std::vector<double> normal_x;
  radial.reserve(2 * kSize * kSize);
  normal_x.reserve(2 * kSize * kSize);
  double pp = 0.0;
  double qq = 0.0;
  double pq = 0.0;
  for (int j = 0; j < kSize; ++j) {
    for (int i = 0; i < kSize; ++i) {
      for (bool upper : {false, true}) {
        const glm::dvec2 s = surface.slopes(i, j, upper);
        pp += s.x * s.x;
        qq += s.y * s.y;
        pq += s.x * s.y;
        const double x = s.x / alpha_x;
        const double y = s.y / alpha_y;
        radial.push_back(x * x + y * y);
        normal_x.push_back(x * std::sqrt(2.0));
      }
    }
  }
  const double count = static_cast<double>(radial.size());
  EXPECT_NEAR(pp / count / (alpha_x * alpha_x / 2.0), 1.0, 1e-9);
  EXPECT_NEAR(qq / count / (alpha_y * alpha_y / 2.0), 1.0, 1e-9);
  const double rho = pq / std::sqrt(pp * qq);
  EXPECT_LT(std::abs(rho), 0.05);
  auto kolmogorov = [count](std::vector<double>& v, auto cdf) {
    std::sort(v.begin(), v.end());
    double d = 0.0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const double f = cdf(v[k]);
      d = std::max({d, std::abs(f - k / count), std::abs(f - (k + 1) / count)});
    }
    return d;
  };
  const double d_radial = kolmogorov(radial, [](double r2) { return 1.0 - std::exp(-r2); });
  const double d_normal = kolmogorov(normal_x, [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); });
  EXPECT_LT(d_radial, 0.02);
  EXPECT_LT(d_normal, 0.02);
  std::printf("alpha %.2f x %.2f seed %d: rho %.4f, Kolmogorov distance radial %.4f, x %.4f\n", alpha_x, alpha_y,
              static_cast<int>(seed), rho, d_radial, d_normal);
}

TEST(MicrosurfaceHeightfield, SlopesAreBeckmann) {
  for (std::uint64_t seed : {1u, 2u, 3u}) check_slopes(0.25, 0.25, seed);
  check_slopes(1.0, 0.1, 4);
}

const Case kFig4{"diffuse 0.25", 0.25, 0.25, true};
const Case kFig5{"diffuse 0.5", 0.5, 0.5, true};
const Case kFig6{"diffuse 1.0", 1.0, 1.0, true};
const Case kFig7{"diffuse 1.0 x 0.1", 1.0, 0.1, true};
const Case kFig8{"conductor 0.25", 0.25, 0.25, false};

// What the position-free walk shows against the heightfield at one
// incidence angle.  The bands are the extremes measured over 6 surfaces and
// ray streams (seeds 1-6 of the runs below, and 3 runs of 200 000 walks;
// docs/experiments/2026-12-03-heightfield-reference.md), rounded outwards,
// then widened by 4 standard errors of the rays of the run at hand, which
// the test computes from its counts.  The surfaces differ among themselves
// more than the rays do (at grazing incidence the ratio spreads by ~+-5 %
// from one surface to the next): the extremes carry that spread.
//   ratio    E_r of the bounces >= 2, position-free over heightfield.  Where
//            Smith's model holds (theta 0.5) they agree within 3 %; towards
//            grazing incidence the real surface sends less light into second
//            bounces than Smith's masking predicts, and the Heitz walk
//            agrees with the position-free one there, so the gap is Smith's,
//            not the walk's (the supplement's Fig. 8 shows the same gap).
//   l1       the lobe's L1 distance beyond what noise alone would give: the
//            bound is l1 + 1.5 x the noise floor of the run's counts (the
//            observed L1 is at most the true distance plus the noise's, and
//            the noise's own spread is ~15 % of its floor); l1 is the
//            largest excess measured plus at least 0.03.
struct Expectation {
  double theta;
  double ratio_lo;
  double ratio_hi;
  double l1;
};

Comparison check(const Case& c, const Expectation& e, int walks, std::uint64_t seed, bool with_heitz = false) {
  const Comparison r = compare(c, e.theta, walks, seed, with_heitz);
  print(c, e.theta, r, with_heitz);
  const Lobe& pf = r.position_free;
  const Lobe& hf = r.heightfield;
  // The tracer: never below the surface, and rays are not lost (a lost ray
  // would be one rising at a tiny angle for a million cells).
  EXPECT_EQ(r.below, 0) << c.name;
  EXPECT_EQ(hf.lost, 0) << c.name;
  EXPECT_EQ(pf.lost, 0) << c.name;
  const double ratio = pf.multiple_energy() / hf.multiple_energy();
  const double sigma = ratio * std::hypot(pf.multiple_sigma() / pf.multiple_energy(),
                                          hf.multiple_sigma() / hf.multiple_energy());
  EXPECT_GT(ratio, e.ratio_lo - 4.0 * sigma) << c.name << " theta " << e.theta;
  EXPECT_LT(ratio, e.ratio_hi + 4.0 * sigma) << c.name << " theta " << e.theta;
  const double l1 = l1_distance(pf.multiple, hf.multiple);
  const double floor = l1_noise_floor(pf.multiple, hf.multiple);
  EXPECT_LT(l1, e.l1 + 1.5 * floor) << c.name << " theta " << e.theta;
  return r;
}

// Walk counts: enough that the bounces >= 2 have some 10 000 walks (their
// energy is then known to ~1 %), fewer where they are common.
void fig4(std::uint64_t seed) {
  check(kFig4, {0.5, 0.97, 1.03, 0.03}, 300000, seed);
  check(kFig4, {1.5, 1.04, 1.10, 0.03}, 300000, seed);
}
void fig5(std::uint64_t seed) {
  check(kFig5, {0.5, 0.97, 1.02, 0.04}, 150000, seed);
  check(kFig5, {1.5, 1.03, 1.14, 0.04}, 150000, seed);
}
void fig6(std::uint64_t seed) {
  check(kFig6, {0.5, 0.97, 1.01, 0.08}, 100000, seed);
  check(kFig6, {1.5, 1.05, 1.11, 0.06}, 100000, seed);
}
void fig7(std::uint64_t seed) {
  check(kFig7, {0.5, 0.97, 1.01, 0.04}, 100000, seed);
  check(kFig7, {1.5, 1.13, 1.19, 0.08}, 100000, seed);
}
// The mirror conductor also against the supplement's printed E_r: at
// theta 1.5 its Fig. 8 gives the second bounce 0.048 for its position-free
// model and for Heitz et al.'s walk, 0.034 for its simulated surface.  The
// tolerance is the printed rounding (0.0005), the spread of the second
// bounce over our surfaces (0.0334-0.0354 on 6, and 0.0484-0.0501 for the
// walks: 0.0015) and 4 standard errors.
void fig8(std::uint64_t seed) {
  check(kFig8, {1.0, 1.05, 1.12, 0.23}, 200000, seed);
  const Comparison r = check(kFig8, {1.5, 1.24, 1.33, 0.42}, 200000, seed, true);
  auto near = [](const Lobe& l, double printed, const char* who) {
    const double e2 = l.energy[1];
    const double tolerance = 0.0005 + 0.0015 + 4.0 * std::sqrt(e2 * (1.0 - e2) / l.walks);
    EXPECT_NEAR(e2, printed, tolerance) << who;
  };
  near(r.position_free, 0.048, "position-free");
  near(r.heitz, 0.048, "Heitz");
  near(r.heightfield, 0.034, "heightfield");
}

TEST(HeightfieldReference, Fig4RoughDiffuse025) { fig4(1); }
TEST(HeightfieldReference, Fig5RoughDiffuse05) { fig5(1); }
TEST(HeightfieldReference, Fig6RoughDiffuse1) { fig6(1); }
TEST(HeightfieldReference, Fig7AnisotropicDiffuse1x01) { fig7(1); }
TEST(HeightfieldReference, Fig8RoughConductor025) { fig8(1); }

// The same checks on other surfaces and ray streams (the bands are not
// tuned to one seed).  By hand:
//   build/tests/skyfarm_tests --gtest_also_run_disabled_tests --gtest_filter='HeightfieldReference.DISABLED_*Seeds'
TEST(HeightfieldReference, DISABLED_OtherSeeds) {
  for (std::uint64_t seed = 2; seed <= 6; ++seed) {
    std::printf("--- seed %d\n", static_cast<int>(seed));
    fig4(seed);
    fig5(seed);
    fig6(seed);
    fig7(seed);
    fig8(seed);
  }
}

// The long version: every case at the supplement's four incidence angles on
// three surfaces, with the Heitz walk: the table of the experiments log.
//   build/tests/skyfarm_tests --gtest_also_run_disabled_tests --gtest_filter='HeightfieldReference.DISABLED_Table'
TEST(HeightfieldReference, DISABLED_Table) {
  for (const Case& c : {kFig4, kFig5, kFig6, kFig7, kFig8}) {
    for (double theta : {0.0, 0.5, 1.0, 1.5}) {
      for (std::uint64_t seed : {1u, 2u, 3u}) {
        const Comparison r = compare(c, theta, 200000, seed, true, true);
        std::printf("seed %d: ", static_cast<int>(seed));
        print(c, theta, r, true, true);
      }
    }
  }
}

}  // namespace
}  // namespace skyfarm::material


// The position-free multiple-bounce walk against an independent reference,
// Heitz et al. 2016's random walk on a microsurface with heights
// (heitz_random_walk.h): binned exit lobes for light from wi, split into the
// single bounce (where the height-correlated position-free model is exact:
// both are Smith's height-correlated G2) and the multiple bounces (where it
// is a Markov approximation of the heights: the energy agrees closely, the
// lobe's shape within a few per cent for isotropic roughness and less well
// for strong anisotropy, as Wang et al. 2022's supplement figures show).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/material/position_free_walk.h"
#include "tests/common/material/heitz_random_walk.h"
#include "tests/common/material/lobe_distance.h"

namespace skyfarm::material {
namespace {

using testing::bin_of;
using testing::kBins;
using testing::kPhiBins;
using testing::kThetaBins;
using testing::l1_distance;

constexpr double kPi = 3.14159265358979323846;

struct Lobes {
  std::vector<double> single = std::vector<double>(kBins, 0.0);
  std::vector<double> multiple = std::vector<double>(kBins, 0.0);
  double multiple_energy = 0.0;
};

// Two-sample chi-square of equal-size samples (counts a, b per bin):
// sum (a - b)^2 / (a + b) over bins with enough counts, ~ chi^2(bins).
double chi_square(const std::vector<double>& a, const std::vector<double>& b, int* dof) {
  double chi = 0.0;
  *dof = 0;
  for (int k = 0; k < kBins; ++k) {
    const double n = a[k] + b[k];
    if (n < 20.0) continue;
    chi += (a[k] - b[k]) * (a[k] - b[k]) / n;
    ++*dof;
  }
  return chi;
}


struct Case {
  std::string name;
  double alpha_x;
  double alpha_y;
  bool diffuse;
  double max_l1;  // measured 0.05-0.08 isotropic (noise ~0.05), 0.12-0.16 for 1 x 0.1
};

void compare(const Case& c, double theta) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, c.alpha_x, c.alpha_y);
  const PositionFreeWalk walk(dist, c.diffuse ? Facet::diffuse(1.0) : Facet::conductor(ConductorFresnel::mirror()),
                              HeightCorrelation::correlated);
  const test::HeitzRandomWalk reference(dist, c.diffuse);
  const glm::dvec3 wi(std::sin(theta), 0.0, std::cos(theta));
  constexpr int kWalks = 200000;
  Lobes ours;
  Lobes theirs;
  RandomSequence rng_ours(11);
  RandomSequence rng_theirs(23);
  for (int i = 0; i < kWalks; ++i) {
    if (const auto exit = walk.trace(wi, rng_ours)) {
      const int k = bin_of(exit->direction);
      ASSERT_GE(k, 0);
      ASSERT_DOUBLE_EQ(exit->weight, 1.0);  // non-absorbing facets
      (exit->bounces == 1 ? ours.single : ours.multiple)[k] += 1.0;
      if (exit->bounces > 1) ours.multiple_energy += 1.0 / kWalks;
    }
    if (const auto exit = reference.trace(wi, rng_theirs)) {
      const int k = bin_of(exit->direction);
      ASSERT_GE(k, 0);
      (exit->order == 1 ? theirs.single : theirs.multiple)[k] += 1.0;
      if (exit->order > 1) theirs.multiple_energy += 1.0 / kWalks;
    }
  }
  int dof = 0;
  const double chi = chi_square(ours.single, theirs.single, &dof);
  // p = 1e-5 for the chi-square with dof <= 48 degrees of freedom lies below 100.
  EXPECT_LT(chi, 100.0) << c.name << " theta " << theta << ": single-bounce lobes differ";
  const double ratio = ours.multiple_energy / theirs.multiple_energy;
  EXPECT_NEAR(ratio, 1.0, 0.025) << c.name << " theta " << theta;
  const double l1 = l1_distance(ours.multiple, theirs.multiple);
  EXPECT_LT(l1, c.max_l1) << c.name << " theta " << theta;
  std::printf("%s theta %.1f: single chi2 %.1f / %d, multiple energy %.4f vs %.4f (ratio %.4f), lobe L1 %.3f\n",
              c.name.c_str(), theta, chi, dof, ours.multiple_energy, theirs.multiple_energy, ratio, l1);
}

TEST(PositionFreeVsHeitzWalk, RoughDiffuse05) {
  for (double theta : {0.0, 1.0}) compare({"diffuse 0.5", 0.5, 0.5, true, 0.10}, theta);
}

TEST(PositionFreeVsHeitzWalk, RoughConductor025) {
  for (double theta : {0.0, 1.0}) compare({"conductor 0.25", 0.25, 0.25, false, 0.12}, theta);
}

TEST(PositionFreeVsHeitzWalk, AnisotropicConductor1x01) {
  for (double theta : {0.0, 1.0}) compare({"conductor 1.0 x 0.1", 1.0, 0.1, false, 0.22}, theta);
}

}  // namespace
}  // namespace skyfarm::material

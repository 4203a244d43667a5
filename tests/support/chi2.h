// Pearson chi-square goodness-of-fit tests for sampling routines: do the
// samples a routine draws follow the density it claims?  Shared by every
// sampling test (warps, phase functions, sun disk, wavelengths, BSDFs).
//
// Method (re-derived from pbrt-v4 src/pbrt/bsdfs_test.cpp and Mitsuba 3
// src/python/python/chi2.py):
//   1. Pre-checks, each a failure with p_value = 0: no samples, a sample that
//      is not finite or lies outside the domain, a pdf value that is negative
//      or not finite, a pdf whose integral over the domain exceeds 1.1, and
//      samples in a cell whose expected count is ~0 (< 1e-6).
//   2. Histogram of the samples on a regular grid of cells; expected count per
//      cell = N * integral of the pdf over the cell by adaptive Simpson
//      quadrature (nested 1-D Simpson in (cos theta, phi) on the sphere, where
//      d omega = d cos(theta) d phi).  The expected counts are NOT renormalised,
//      so a pdf that misses mass fails.
//   3. Cells with expected count < 5 are pooled, smallest first, into groups
//      that each expect >= 5 (the grouping depends on the expected counts
//      only); statistic = sum (O - E)^2 / E over the cells and groups,
//      dof = their number - 1.
//   4. p_value = Q(dof/2, statistic/2), the regularised upper incomplete gamma
//      function (series / continued fraction, Numerical Recipes §6.2 style).
// The caller compares p_value with its significance level (0.01 in this
// project; Sidak-correct it with sidak_significance() when one case runs
// several tests).  `detail` always summarises the run and lists the cells
// that contribute most to the statistic, so a failing assertion shows where
// the sampler and the pdf disagree.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace skyfarm::testing {

struct Chi2Result {
  double statistic;
  int dof;
  double p_value;
  std::string detail;
};

// samples in [a,b]; expected count per bin from adaptive Simpson integration of pdf; cells with expected < 5 pooled.
Chi2Result chi2_test_1d(const std::function<double(double)>& pdf, const std::vector<double>& samples, double a,
                        double b, int bins);

// unit vectors binned in (cos θ, φ) about +z; pdf per steradian integrated over each cell (adaptive/2-D Simpson in (cos θ, φ)).
Chi2Result chi2_test_sphere(const std::function<double(const glm::dvec3&)>& pdf,
                            const std::vector<glm::dvec3>& samples, int cos_theta_bins, int phi_bins);

// Q(a, x) = Gamma(a, x) / Gamma(a), the regularised upper incomplete gamma
// function, a > 0, x >= 0 (relative accuracy ~1e-14, also for tiny Q).
double regularized_gamma_q(double a, double x);

// P(X >= statistic) for X ~ chi-square with dof degrees of freedom.
double chi2_survival(double statistic, int dof);

// Per-test significance so that num_tests independent tests together have
// significance alpha (Sidak): 1 - (1 - alpha)^(1/num_tests).
double sidak_significance(double alpha, int num_tests);

}  // namespace skyfarm::testing

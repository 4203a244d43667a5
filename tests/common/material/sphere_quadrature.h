// Numerical quadrature over the hemisphere of microfacet normals for the
// material tests.  The integrand is f(wm), wm a unit vector with wm.z >= 0,
// integrated against the solid angle over a region theta in [theta0,
// theta1], phi in [phi0, phi1] (the whole hemisphere by default).
//
// Composite Gauss-Legendre in both angles.  In the polar angle the pieces
// are graded so that the integrand is smooth on each:
//   - around the pole, tan(theta) doubling from alpha_min / 16 to
//     alpha_max * 4096 (the distributions are peaked within tan(theta) ~
//     alpha and have long tails);
//   - at each "kink" direction k the integrand may carry a factor
//     <k . wm>+, whose crease on the ring of azimuth phi lies at the theta
//     where k . wm = 0; the pieces split there and shrink geometrically
//     towards it on both sides, because below the macro surface nearly all
//     of the mass of <k . wm>+ D(wm) hugs that crease.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

namespace skyfarm::material::test {

constexpr double kPi = 3.14159265358979323846;

struct GaussLegendre {
  std::vector<double> x;  // nodes on [-1, 1]
  std::vector<double> w;  // weights
};

// Nodes and weights of the n-point rule: roots of P_n by Newton's method.
inline GaussLegendre gauss_legendre(int n) {
  GaussLegendre rule;
  rule.x.resize(n);
  rule.w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0;
      double p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double step = p1 / dp;
      z -= step;
      if (std::abs(step) < 1e-16) break;
    }
    rule.x[i] = z;
    rule.w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
  return rule;
}

struct Region {
  double theta0 = 0.0;
  double theta1 = kPi / 2.0;
  double phi0 = 0.0;
  double phi1 = 2.0 * kPi;
};

template <class F>
double integrate_hemisphere(F&& f, double alpha_min, double alpha_max, const std::vector<glm::dvec3>& kinks = {},
                            const Region& region = {}, int phi_pieces = 48, int kink_levels = 24) {
  static const GaussLegendre gl = gauss_legendre(8);
  std::vector<double> fixed{region.theta0, region.theta1};
  for (double t = alpha_min / 16.0; t < alpha_max * 4096.0; t *= 2.0) {
    const double theta = std::atan(t);
    if (theta > region.theta0 && theta < region.theta1) fixed.push_back(theta);
  }
  const double phi_step = (region.phi1 - region.phi0) / phi_pieces;
  double total = 0.0;
  std::vector<double> b;
  for (int piece = 0; piece < phi_pieces; ++piece) {
    for (std::size_t jp = 0; jp < gl.x.size(); ++jp) {
      const double phi = region.phi0 + phi_step * (piece + 0.5 + 0.5 * gl.x[jp]);
      const double cp = std::cos(phi);
      const double sp = std::sin(phi);
      b = fixed;
      for (const glm::dvec3& k : kinks) {
        // k . wm = sin(theta) (k.x cos phi + k.y sin phi) + cos(theta) k.z = 0.
        const double a = k.x * cp + k.y * sp;
        double crease = std::atan2(-k.z, a);
        if (crease < 0.0) crease += kPi;
        if (!(crease > region.theta0 && crease < region.theta1)) continue;
        b.push_back(crease);
        for (int level = 1; level <= kink_levels; ++level) {
          const double scale = std::ldexp(1.0, -level);
          b.push_back(crease + (region.theta1 - crease) * scale);
          b.push_back(crease - (crease - region.theta0) * scale);
        }
      }
      std::sort(b.begin(), b.end());
      double ring = 0.0;
      for (std::size_t k = 0; k + 1 < b.size(); ++k) {
        const double mid = 0.5 * (b[k] + b[k + 1]);
        const double half = 0.5 * (b[k + 1] - b[k]);
        if (half <= 0.0) continue;
        for (std::size_t i = 0; i < gl.x.size(); ++i) {
          const double theta = mid + half * gl.x[i];
          const double st = std::sin(theta);
          ring += half * gl.w[i] * st * f(glm::dvec3(st * cp, st * sp, std::cos(theta)));
        }
      }
      total += 0.5 * phi_step * gl.w[jp] * ring;
    }
  }
  return total;
}

}  // namespace skyfarm::material::test

#include "common/material/smith_full_sphere.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace skyfarm::material {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

// Lambda(-w) = -1 - Lambda(w): the odd extension of Smith's Lambda, which is
// what makes the supplement's eq. 3 and eq. 12 hold below the macro surface
// (its eq. 23 writes -1/(1 + Lambda(d)) = 1/Lambda(-d) for d below).
double lambda_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& w) {
  const double lambda_up = distribution.lambda(w);  // depends on |w.z| only
  return w.z > 0.0 ? lambda_up : -1.0 - lambda_up;
}

// Wang et al. 2022, supplement eq. 3:
//   G1^dist(w) = |1 / (1 + Lambda(w))|
//              = 1 / (1 + Lambda(w))   if w . wg > 0,
//              = -1 / (1 + Lambda(w))  = 1 / Lambda(-w)  otherwise.
// Evaluated from Lambda of the upper-hemisphere direction, without forming
// 1 + (-1 - Lambda), which would lose the small Lambda near normal incidence.
double g1_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& w) {
  const double lambda_up = distribution.lambda(w);
  if (w.z > 0.0) return 1.0 / (1.0 + lambda_up);
  if (lambda_up == 0.0) return kInfinity;
  return 1.0 / lambda_up;
}

// Wang et al. 2022, supplement eq. 12 (eq. 5 above, eq. 11 below):
//   G2^dist(wi, wo) = 1 / (-Lambda(-wi) + Lambda(wo)) = 1 / (1 + Lambda(wi) + Lambda(wo))
//                                                        if wi . wg > 0,
//                   = 1 / (Lambda(-wi) + Lambda(wo))     if wi . wg <= 0,
// Lambda on the full sphere; both cases are 1 / (|Lambda(-wi)| + Lambda(wo))
// as in eq. 16.  Eq. 13: the last bounce uses this same function.
double g2_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& wi,
                      const glm::dvec3& wo) {
  glm::dvec3 in = wi;
  glm::dvec3 out = wo;
  if (out.z <= 0.0) std::swap(in, out);
  if (out.z <= 0.0) return 0.0;  // both below: outside the model
  const double lambda_out = distribution.lambda(out);
  const double lambda_in = distribution.lambda(in);  // Lambda of the upper direction +-in
  const double denominator = in.z > 0.0 ? 1.0 + lambda_in + lambda_out : lambda_in + lambda_out;
  if (denominator == 0.0) return kInfinity;
  return 1.0 / denominator;
}

// Wang et al. 2022, supplement eq. 17 (eq. 14 and eq. 16):
//   G2^{i<k}(wi, wo) = G1^dist(wi) - G2^dist(wi, wo)   if wo . wg > 0,
//                    = G1^dist(wi)                      if wo . wg <= 0,
// from G2^dist = integral G1(wi, h) G1(wo, h) P(h) dh (eq. 15): the middle
// bounce needs wo blocked, i.e. G1(wi, h) (1 - G1(wo, h)) over the heights.
// (The supplement's eq. 26 subtracts from G1^dist of the outgoing direction
// instead; eq. 16's derivation gives G1^dist(wi), used here.)
double g2_middle_bounce(const MicrofacetDistribution& distribution, const glm::dvec3& wi,
                        const glm::dvec3& wo) {
  const double g1_in = g1_full_sphere(distribution, wi);
  if (wo.z <= 0.0) return g1_in;
  if (std::isinf(g1_in)) return g1_in;
  // G2 <= G1 in exact arithmetic; the clamp removes rounding below zero.
  return std::max(g1_in - g2_full_sphere(distribution, wi, wo), 0.0);
}

}  // namespace skyfarm::material

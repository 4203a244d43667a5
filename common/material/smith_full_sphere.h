// Smith shadowing-masking over the full sphere of directions, for paths that
// bounce several times on the microsurface and so travel below the macro
// surface between bounces (Wang et al. 2022, "Position-free Monte Carlo
// computation of multiple-bounce Smith microfacet BSDFs", supplement §1).
//
// Parameters
//   distribution  the microfacet distribution (its lambda() is Smith's Lambda
//                 for the upper hemisphere).
//   w, wi, wo     unit directions in the local shading frame (+z = macro
//                 normal), pointing away from the surface; any of them may be
//                 below the macro surface (w.z < 0) where stated.
//
// The extension rests on Lambda over the full sphere: for w below the macro
// surface, Lambda(w) = -1 - Lambda(-w) (lambda_full_sphere).  With it
//   1 + Lambda(w) =  integral <w.wm>+ D(wm) dwm / (w.z)       (w.z > 0)
//   1 + Lambda(w) = -integral <w.wm>+ D(wm) dwm / |w.z|       (w.z < 0)
// so |1 + Lambda(w)| |w.z| is always the projected area of the normals facing
// w, which is what every formula below uses.
//
// Not defined: w exactly -z (no normal faces it: G1 is infinite), and G2 with
// both directions below the macro surface (no such pair occurs in the model:
// a path enters and leaves above it); those return +infinity and 0.
#pragma once

#include <glm/vec3.hpp>

#include "common/material/microfacet_distribution.h"

namespace skyfarm::material {

// Lambda(w) for w anywhere on the sphere: Smith's Lambda above the macro
// surface, -1 - Lambda(-w) below it.
double lambda_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& w);

// The full-spherical distant masking G1^dist(w) = |1 / (1 + Lambda(w))|; for
// w below the macro surface it equals 1 / Lambda(-w) and may exceed 1.
double g1_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& w);

// The height-correlated shadowing-masking G2^dist(wi, wo) (the last bounce,
// G2^{i=k}): wo above the macro surface, wi on either side.  If wo is the one
// below, the roles swap (the function is symmetric).
double g2_full_sphere(const MicrofacetDistribution& distribution, const glm::dvec3& wi,
                      const glm::dvec3& wo);

// The middle-bounce form G2^{i<k}(wi, wo): the probability that light along
// wi reaches the surface and the ray leaving along wo is blocked (so that the
// path bounces again).
double g2_middle_bounce(const MicrofacetDistribution& distribution, const glm::dvec3& wi,
                        const glm::dvec3& wo);

}  // namespace skyfarm::material

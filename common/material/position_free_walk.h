// The position-free multiple-bounce Smith microsurface (Wang et al. 2022,
// "Position-free Monte Carlo computation of multiple-bounce Smith microfacet
// BSDFs"): light bounces k >= 1 times on facets whose normals follow the
// distribution, and the paths are sequences of DIRECTIONS only (no heights):
// each bounce is a vertex term (the facet's BSDF against the visible-normal
// density) and each direction between bounces a segment term (full-sphere
// shadowing-masking, smith_full_sphere.h).
//
// The product of those terms along a path is a Markov chain over directions,
// which this class walks.  The ray arrives along -v (v points back towards
// where it came from; it may be below the macro surface inside the walk):
//   1. it meets a facet wm drawn from the full-sphere visible normals D_v
//      (their normalisation is G1^dist(v), the "p" half of a segment term);
//   2. the facet scatters it to w (mirror, Lambert, or Fresnel-weighted
//      reflect/refract), the throughput taking the facet's albedo / F;
//   3. it leaves the surface with probability
//        uncorrelated:  G1^dist(w)             (w above, else 0)
//        correlated:    G2^dist(v, w) / G1^dist(v)
//      (supplement eq. 13 over eq. 3: the last-bounce over the arrival term)
//      and otherwise bounces again with v = -w (supplement eq. 17: the
//      middle-bounce term G1^dist(v) - G2^dist(v, w) over G1^dist(v) is the
//      complementary probability).
// With the arrival factor G1^dist of step 1 these are exactly the paper's
// segment terms: uncorrelated s = e p with e = 1 - G1^dist(w) or 1 and
// p = G1^dist (supplement eqs. 18-23), correlated s = G2^{i<k} and G2^{i=k}
// (eqs. 13, 17, 25).  A walk whose facets do not absorb (F = 1, albedo 1,
// any dielectric) keeps all the energy: every walk leaves eventually.
//
// Estimators
//   unidirectional  walk from the light direction and, at every vertex, add
//                   the facet's scattering density towards the viewer times
//                   its leaving probability (next-event estimation: the
//                   paper's connection of the path to the fixed last
//                   direction); analytic for mirror and dielectric facets,
//                   one visible normal for Lambertian facets.
//   bidirectional   (every facet kind) a walk from the light
//                   and one from the viewer, every prefix of one joined to
//                   every prefix of the other at one vertex; the strategies
//                   that can make a path of k bounces (the joining vertex
//                   1..k) are weighted by the balance heuristic over their
//                   densities.  The reverse walk's vertex terms follow from
//                   the forward ones because D_v(wm) |v.z| / G1(v) =
//                   <v.wm>+ D(wm) is symmetric.  Mirror facets: the joining
//                   vertex is evaluated analytically (its half vector) and
//                   the densities are over directions; it removes the spikes
//                   of the unidirectional connection through a sharp facet
//                   density seen from a random direction (smooth surfaces,
//                   several bounces).  Lambertian facets: the joining vertex
//                   has no closed form, so each bounce's facet normal is part
//                   of the path (the join takes the normal either walk drew
//                   there, the two shared by a generalised balance
//                   heuristic) and the densities are over (normal,
//                   direction); the gain is smaller, the one-way
//                   connection through a Lambertian facet being smooth
//                   already.  Dielectric
//                   facets: as mirror facets, on both sides of the interface
//                   (directions in the frame of their side); a reverse
//                   refraction weighs eta^2 more than a reverse reflection.
//
// Parameters
//   distribution  the microfacet distribution.
//   facet         what one facet does: FacetKind::conductor (fresnel),
//                 ::diffuse (albedo), ::dielectric (eta = n_inside /
//                 n_outside, the inside below the macro surface).
//   correlation   HeightCorrelation::uncorrelated (reciprocal, supplement
//                 §2.1) or ::correlated (closer to a surface with heights,
//                 not reciprocal, supplement §2.2).
//   max_bounces   a cap on the walk (default 256); a non-absorbing walk at
//                 alpha = 2 leaves within a few tens of bounces, so the
//                 truncation is far below the noise.  The bidirectional
//                 estimator caps each walk at min(max_bounces, 64) (and,
//                 for diffuse and dielectric facets, the paths it joins at
//                 that many bounces).
//
// Inside a dielectric the walk uses the mirrored frame (w -> -w), in which
// the inside medium is above the microsurface; the relative index inverts.
// The correlated leaving term across a refraction pairs directions of the two
// frames (an approximation of the height correlation through the interface,
// as pbrt-v4 does for single-bounce transmission).
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "common/material/conductor_fresnel.h"
#include "common/material/microfacet_distribution.h"
#include "common/material/random_sequence.h"

namespace skyfarm::material {

enum class FacetKind { conductor, diffuse, dielectric };
enum class HeightCorrelation { uncorrelated, correlated };

struct Facet {
  FacetKind kind = FacetKind::conductor;
  ConductorFresnel fresnel = ConductorFresnel::mirror();  // conductor
  double albedo = 1.0;                                    // diffuse
  double eta = 1.5;                                       // dielectric

  static Facet conductor(ConductorFresnel f) { return {FacetKind::conductor, f, 1.0, 1.5}; }
  static Facet diffuse(double albedo) { return {FacetKind::diffuse, ConductorFresnel::mirror(), albedo, 1.5}; }
  static Facet dielectric(double eta) { return {FacetKind::dielectric, ConductorFresnel::mirror(), 1.0, eta}; }
};

class PositionFreeWalk {
 public:
  PositionFreeWalk(const MicrofacetDistribution& distribution, Facet facet, HeightCorrelation correlation,
                   int max_bounces = 256);

  // One unbiased estimate of f(wo, wi) |wo.z|, light arriving from wi and
  // leaving towards wo (either may be below the macro surface for a
  // dielectric), by the unidirectional estimator.  Bounce orders outside
  // [min_order, max_order] are left out (1, 1 is the single-bounce BSDF).
  double estimate(const glm::dvec3& wi, const glm::dvec3& wo, RandomSequence& rng, int min_order = 1,
                  int max_order = 1 << 30) const;

  // One estimate of f(wo, wi) |wo.z| by the bidirectional estimator (both
  // directions above the macro surface, or on either side for a dielectric).
  double estimate_bidirectional(const glm::dvec3& wi, const glm::dvec3& wo, RandomSequence& rng) const;

  // One walk from the light direction wi to its exit: the direction it leaves
  // along and the energy it carries (its density over the exit direction,
  // times the energy, is f(wo, wi) |wo.z|); nullopt if the walk hit the cap.
  struct Exit {
    glm::dvec3 direction;
    double weight = 0.0;
    int bounces = 0;
  };
  std::optional<Exit> trace(const glm::dvec3& wi, RandomSequence& rng) const;

  const MicrofacetDistribution& distribution() const { return distribution_; }
  const Facet& facet() const { return facet_; }

 private:
  // The probability that a ray which arrived along -v and left its facet
  // along w leaves the surface (step 3 above).
  double leave_probability(const glm::dvec3& v, const glm::dvec3& w) const;
  // The facet's scattering density from v towards `target` (in the frame of
  // the target's side: target.z > 0), times the energy kept: the
  // next-event term of one vertex.  same_side: the target is on the side of
  // v (reflection); eta: the relative index seen from v's side.
  double scatter_density(const glm::dvec3& v, const glm::dvec3& wm, bool same_side, const glm::dvec3& target,
                         double eta) const;
  // Scatters at the facet wm: the new direction (in the frame of the side it
  // travels on), whether it crossed the interface, and the energy kept.
  struct Scatter {
    glm::dvec3 w;
    bool crossed = false;
    double weight = 0.0;
  };
  std::optional<Scatter> scatter(const glm::dvec3& v, const glm::dvec3& wm, double eta, RandomSequence& rng) const;
  // The bidirectional estimator for Lambertian and dielectric facets
  // (estimate_bidirectional).
  double estimate_bidirectional_diffuse(const glm::dvec3& wi, const glm::dvec3& wo, RandomSequence& rng) const;
  double estimate_bidirectional_dielectric(const glm::dvec3& wi, const glm::dvec3& wo, RandomSequence& rng) const;

  MicrofacetDistribution distribution_;
  Facet facet_;
  HeightCorrelation correlation_;
  int max_bounces_;
};

}  // namespace skyfarm::material

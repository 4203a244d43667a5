// A test-only, independent reference for the multiple-bounce microsurface:
// the random walk on a Smith microsurface WITH heights of Heitz, Hanika,
// d'Eon and Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the
// Smith model" (its Algorithm 1 and the uniform height distribution of its
// supplemental code).  The position-free walk replaces the heights by
// directional segment terms; this one tracks the height of every bounce, so
// its lobe is the one the position-free model approximates.
//
// Height distribution: uniform on [-1, 1] (P1 = 1/2, C1(h) = (h + 1) / 2);
// the walk's results do not depend on that choice (Heitz et al. 2016, §5.2).
// Masking at height h: G1(w, h) = C1(h)^Lambda(w) for w above the macro
// surface (Smith's height-dependent masking), 0 below.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/microfacet_distribution.h"
#include "common/material/random_sequence.h"
#include "common/material/smith_full_sphere.h"

namespace skyfarm::material::test {

class HeitzRandomWalk {
 public:
  // diffuse: Lambertian facets of albedo 1; otherwise perfect mirrors.
  HeitzRandomWalk(const MicrofacetDistribution& distribution, bool diffuse)
      : distribution_(distribution), diffuse_(diffuse) {}

  struct Exit {
    glm::dvec3 direction;
    int order = 0;
  };

  // One walk for light arriving from wi (wi.z > 0); nullopt past 256 bounces.
  std::optional<Exit> trace(const glm::dvec3& wi, RandomSequence& rng) const {
    glm::dvec3 wr = -wi;  // the direction the ray travels
    double hr = 1.0 + inv_c1(0.999);
    for (int order = 0; order <= 256; ++order) {
      hr = sample_height(wr, hr, rng.next());
      if (hr == kEscaped) return Exit{wr, order};
      if (!std::isfinite(hr)) return std::nullopt;
      const glm::dvec3 wm = distribution_.sample_visible_normal(-wr, {rng.next(), rng.next()});
      if (diffuse_) {
        wr = sample_cosine_around(wm, {rng.next(), rng.next()});
      } else {
        wr = reflect_about(-wr, wm);
      }
    }
    return std::nullopt;
  }

 private:
  static constexpr double kEscaped = std::numeric_limits<double>::max();

  static double c1(double h) { return std::clamp(0.5 * (h + 1.0), 0.0, 1.0); }
  static double inv_c1(double u) { return std::clamp(2.0 * u - 1.0, -1.0, 1.0); }

  // Heitz et al. 2016, Algorithm 1 ("sample the next height"): the ray from
  // height h0 along wr meets the surface at the height whose CDF is
  //   1 - U = (C1(h0) / C1(h))^(-Lambda(wr))  i.e. C1(h) = C1(h0) / (1 - U)^(1 / Lambda(wr)),
  // unless it escapes, with probability G1(wr, h0) = C1(h0)^Lambda(wr) for
  // wr above the macro surface (Lambda over the full sphere: negative below,
  // which makes the new height lower).
  double sample_height(const glm::dvec3& wr, double h0, double u) const {
    if (wr.z > 0.9999) return kEscaped;
    if (wr.z < -0.9999) return inv_c1(u * c1(h0));
    if (std::abs(wr.z) < 1e-4) return h0;
    const double lambda = lambda_full_sphere(distribution_, wr);
    const double g1 = wr.z > 0.0 ? std::pow(c1(h0), lambda) : 0.0;
    if (u > 1.0 - g1) return kEscaped;
    return inv_c1(c1(h0) / std::pow(1.0 - u, 1.0 / lambda));
  }

  MicrofacetDistribution distribution_;
  bool diffuse_;
};

}  // namespace skyfarm::material::test

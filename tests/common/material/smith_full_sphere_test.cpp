// Oracles for the full-sphere Smith functions (Wang et al. 2022,
// supplement §1): each closed form against the projected-area integral it
// is defined by, evaluated by quadrature, for directions above and below the
// macro surface; the middle-bounce form against its height integral.
#include "common/material/smith_full_sphere.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "common/material/microfacet_distribution.h"
#include "tests/common/material/sphere_quadrature.h"

namespace skyfarm::material {
namespace {

using test::integrate_hemisphere;
using test::kPi;

struct Roughness {
  double alpha_x;
  double alpha_y;
};

const MicrofacetModel kModels[] = {MicrofacetModel::ggx, MicrofacetModel::beckmann};
const Roughness kRoughnesses[] = {{0.2, 0.2}, {0.5, 0.5}, {1.0, 1.0}, {1.0, 0.1}};

std::string label(MicrofacetModel model, const Roughness& r) {
  return std::string(model == MicrofacetModel::ggx ? "ggx" : "beckmann") + " alpha " +
         std::to_string(r.alpha_x) + "," + std::to_string(r.alpha_y);
}

glm::dvec3 direction(double theta_deg, double phi) {
  const double t = theta_deg * kPi / 180.0;
  return {std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t)};
}

// Integral of <w . wm>+ D(wm) dwm: the projected area of the normals facing w.
double facing_area(const MicrofacetDistribution& dist, const glm::dvec3& w) {
  return integrate_hemisphere([&](const glm::dvec3& wm) { return std::max(glm::dot(w, wm), 0.0) * dist.D(wm); },
                              std::min(dist.alpha_x(), dist.alpha_y()), std::max(dist.alpha_x(), dist.alpha_y()), {w});
}

TEST(SmithFullSphere, LambdaIsOddExtension) {
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : kRoughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta : {0.0, 20.0, 50.0, 85.0}) {
        SCOPED_TRACE(label(model, r) + " theta " + std::to_string(theta));
        const glm::dvec3 w = direction(theta, 0.5);
        EXPECT_EQ(lambda_full_sphere(dist, w), dist.lambda(w));
        EXPECT_DOUBLE_EQ(lambda_full_sphere(dist, -w), -1.0 - dist.lambda(w));
      }
    }
  }
}

// Supplement eq. 3 against eq. 4: G1^dist(w) = |w . z| / integral <w . wm>+
// D(wm) dwm, above and below the macro surface.
TEST(SmithFullSphere, G1MatchesProjectedAreaIntegralAboveAndBelow) {
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : kRoughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta : {10.0, 45.0, 80.0, 95.0, 110.0, 135.0, 160.0}) {
        for (double phi : {0.0, 1.1}) {
          SCOPED_TRACE(label(model, r) + " theta " + std::to_string(theta) + " phi " + std::to_string(phi));
          const glm::dvec3 w = direction(theta, phi);
          const double numeric = std::abs(w.z) / facing_area(dist, w);
          const double g1 = g1_full_sphere(dist, w);
          EXPECT_NEAR(g1, numeric, 1e-3 * numeric);
          if (w.z > 0.0) {
            EXPECT_DOUBLE_EQ(g1, dist.g1(w));
          }
        }
      }
    }
  }
}

// Below the macro surface few normals face w, and G1^dist exceeds 1 (the
// supplement's Fig. 2, GGX alpha = 1).
TEST(SmithFullSphere, G1ExceedsOneWellBelowTheSurface) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 1.0, 1.0);
  EXPECT_GT(g1_full_sphere(dist, direction(160.0, 0.0)), 1.0);
  EXPECT_LT(g1_full_sphere(dist, direction(20.0, 0.0)), 1.0);
}

// Supplement eqs. 7 and 9: G2^dist(wi, wo) = |wi . z| (wo . z) / integral
// D(wm) [<wi . wm>+ (wo . z) + <-wo . wm>+ |wi . z|] dwm, wo above, wi on
// either side.
TEST(SmithFullSphere, G2MatchesProjectedAreaIntegral) {
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : kRoughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta_i : {15.0, 70.0, 100.0, 140.0}) {
        for (double theta_o : {5.0, 60.0, 85.0}) {
          SCOPED_TRACE(label(model, r) + " theta_i " + std::to_string(theta_i) + " theta_o " +
                       std::to_string(theta_o));
          const glm::dvec3 wi = direction(theta_i, 0.3);
          const glm::dvec3 wo = direction(theta_o, 2.5);
          const double numeric =
              std::abs(wi.z) * wo.z /
              integrate_hemisphere(
                  [&](const glm::dvec3& wm) {
                    return dist.D(wm) * (std::max(glm::dot(wi, wm), 0.0) * wo.z +
                                         std::max(-glm::dot(wo, wm), 0.0) * std::abs(wi.z));
                  },
                  std::min(r.alpha_x, r.alpha_y), std::max(r.alpha_x, r.alpha_y), {wi, -wo});
          const double g2 = g2_full_sphere(dist, wi, wo);
          EXPECT_NEAR(g2, numeric, 5e-4 * numeric);
          // Symmetric; never above the masking of the direction that may be below.
          EXPECT_DOUBLE_EQ(g2_full_sphere(dist, wo, wi), g2);
          EXPECT_LE(g2, g1_full_sphere(dist, wi) * (1.0 + 1e-12));
          // Both above: heights correlate the two visibilities positively.
          if (wi.z > 0.0) {
            EXPECT_GE(g2, dist.g1(wi) * dist.g1(wo));
          }
        }
      }
    }
  }
}

// Supplement eq. 16 from eq. 15: with Smith's height-uncorrelated-per-
// direction masking G1(w, h) = C(h)^Lambda(w) (C the height CDF), the middle
// bounce is integral_0^1 c^Lambda(wi) (1 - c^Lambda(wo)) dc for wi, wo above;
// with wo below the ray always meets the surface (eq. 14).
TEST(SmithFullSphere, MiddleBounceMatchesHeightIntegral) {
  const test::GaussLegendre gl = test::gauss_legendre(40);
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : kRoughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double theta_i : {0.0, 30.0, 75.0, 89.0}) {
        for (double theta_o : {10.0, 60.0, 88.0}) {
          SCOPED_TRACE(label(model, r) + " theta_i " + std::to_string(theta_i) + " theta_o " +
                       std::to_string(theta_o));
          const glm::dvec3 wi = direction(theta_i, 0.2);
          const glm::dvec3 wo = direction(theta_o, 1.7);
          const double li = dist.lambda(wi);
          const double lo = dist.lambda(wo);
          // c = s^4 takes the endpoint singularities of c^Lambda out of the way.
          double numeric = 0.0;
          for (std::size_t k = 0; k < gl.x.size(); ++k) {
            const double s = 0.5 * (gl.x[k] + 1.0);
            const double c = s * s * s * s;
            numeric += 0.5 * gl.w[k] * std::pow(c, li) * (1.0 - std::pow(c, lo)) * 4.0 * s * s * s;
          }
          EXPECT_NEAR(g2_middle_bounce(dist, wi, wo), numeric, 1e-9);
          EXPECT_DOUBLE_EQ(g2_middle_bounce(dist, wi, -wo), g1_full_sphere(dist, wi));
        }
      }
      // The internal direction below the surface: G1^dist(wi) - G2^dist(wi, wo),
      // between 0 and G1^dist(wi).
      for (double theta_i : {95.0, 130.0, 170.0}) {
        const glm::dvec3 wi = direction(theta_i, 0.2);
        const glm::dvec3 wo = direction(40.0, 1.0);
        const double middle = g2_middle_bounce(dist, wi, wo);
        if (std::isinf(g1_full_sphere(dist, wi))) {
          // Lambda(-wi) underflows (Beckmann, smooth, wi near -z): G1 beyond
          // the doubles, and so the middle bounce.
          EXPECT_TRUE(std::isinf(middle));
          continue;
        }
        EXPECT_NEAR(middle, g1_full_sphere(dist, wi) - g2_full_sphere(dist, wi, wo), 1e-12 * (1.0 + middle));
        EXPECT_GE(middle, 0.0);
        EXPECT_LE(middle, g1_full_sphere(dist, wi));
      }
    }
  }
}

// Extreme roughness and grazing directions on either side: finite and
// non-negative.
TEST(SmithFullSphere, StableAtExtremeRoughnessAndGrazing) {
  const Roughness roughnesses[] = {{1e-4, 1e-4}, {2.0, 2.0}, {1e-4, 2.0}};
  for (MicrofacetModel model : kModels) {
    for (const Roughness& r : roughnesses) {
      const MicrofacetDistribution dist(model, r.alpha_x, r.alpha_y);
      for (double z : {1e-300, 1e-12, 1e-6, 1e-3}) {
        for (double sign : {1.0, -1.0}) {
          SCOPED_TRACE(label(model, r) + " z " + std::to_string(sign * z));
          const double s = std::sqrt(1.0 - z * z);
          const glm::dvec3 w(s * 0.6, s * 0.8, sign * z);
          const glm::dvec3 up(0.0, 0.6, 0.8);
          for (double v : {g1_full_sphere(dist, w), g2_full_sphere(dist, w, up), g2_middle_bounce(dist, w, up),
                           g2_middle_bounce(dist, up, w)}) {
            EXPECT_TRUE(std::isfinite(v));
            EXPECT_GE(v, 0.0);
          }
          EXPECT_FALSE(std::isnan(lambda_full_sphere(dist, w)));
        }
      }
    }
  }
}

}  // namespace
}  // namespace skyfarm::material

// The closed form of a Lambertian sphere of albedo rho lit by the sun's
// disk (radius alpha, radiance L_sun) and nothing else:
//   L = (rho / pi) integral_disk n.w L_sun dw = rho L_sun sin^2(alpha) (n.s),
// the disk wholly above the tangent plane (the mean of w over a cone of
// half-angle alpha is s (1 + cos alpha) / 2 times its solid angle
// 2 pi (1 - cos alpha)); on the far side 0.  Probes 15 directions over the
// sphere's face (centre_from_camera: its centre from the observer, metres)
// and checks each within 4 standard errors, at least 4 lit and 2 dark.
#pragma once

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "common/render/radiance_probe.h"

namespace skyfarm::testing {

inline void expect_sunlit_lambertian_sphere(const Scene& scene, const glm::dvec3& centre_from_camera, double radius,
                                            double rho) {
  const glm::dvec3& c = centre_from_camera;
  const glm::dvec3 s = scene.sun().direction();
  SampledWavelengths wl;
  wl.lambda_nm = {450.0, 550.0, 650.0, 750.0};
  wl.pdf.fill(1.0);
  const SampledSpectrum Le = scene.medium().path_coefficients(wl, &scene.sun()).sun_radiance;
  const double sin_alpha = std::sin(scene.sun().angular_radius_rad());
  const double distance = glm::length(c);
  std::vector<glm::dvec3> dirs;
  for (double dx : {-0.12, -0.06, 0.0, 0.06, 0.12})
    for (double dz : {-0.1, 0.0, 0.1}) dirs.push_back(glm::normalize(c + distance * glm::dvec3(dx, 0, dz)));
  const ProbeResult r = probe_radiance(scene, dirs, {450.0, 550.0, 650.0, 750.0}, 256, 7, 2);
  EXPECT_EQ(r.counters.nonfinite, 0u);
  int lit = 0, dark = 0;
  for (std::size_t d = 0; d < dirs.size(); ++d) {
    // Where the ray meets the sphere: the outward normal there.
    const double b = glm::dot(-c, dirs[d]), q = glm::dot(c, c) - radius * radius;
    ASSERT_GE(b * b - q, 0.0) << "direction " << d << " misses the sphere";
    const glm::dvec3 n = glm::normalize((-b - std::sqrt(b * b - q)) * dirs[d] - c);
    const double cos_s = glm::dot(n, s);
    // Only where the whole disk is on one side of the tangent plane.
    if (std::abs(cos_s) < 2.0 * sin_alpha) continue;
    for (std::size_t w = 0; w < 4; ++w) {
      const double expected = cos_s > 0.0 ? rho * Le[static_cast<int>(w)] * sin_alpha * sin_alpha * cos_s : 0.0;
      EXPECT_NEAR(r.radiance[d][w], expected, 4.0 * r.standard_error[d][w] + 1e-6 * Le[0] * sin_alpha * sin_alpha)
          << "direction " << d << " cos " << cos_s;
    }
    (cos_s > 0.0 ? lit : dark) += 1;
  }
  EXPECT_GT(lit, 3);
  EXPECT_GT(dark, 1);
}

}  // namespace skyfarm::testing

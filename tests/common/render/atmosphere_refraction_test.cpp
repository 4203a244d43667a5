// The renderers' refraction model (common/render/atmosphere_refraction.h,
// bent_path.h) against the reference shells and tables of
// common/atmosphere/ (themselves checked against Auer & Standish's integral,
// docs/physics.md, "Refraction").
#include "common/render/atmosphere_refraction.h"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "common/atmosphere/refracted_ray.h"
#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double kR = 6371000.0;

const AtmosphereRefraction& model() { return *AtmosphereRefraction::shared(kR, 100000.0); }

// The coarse rendering shells bend a ray as the reference shells
// (|d(n - 1)| <= 3e-7) do: the horizontal ray from the ground (33.0' of
// refraction, the largest) within 1", a ray at 5 deg within 0.1".
TEST(AtmosphereRefraction, RenderShellsMatchTheReferenceShells) {
  const RefractiveShells fine = RefractiveShells::from_profile(us76_refractivity_profile(550.0, kR, 100000.0));
  for (const double zenith : {90.0, 89.5, 85.0}) {
    const double reference = trace_refracted_ray(fine, kR, zenith, false).bending_rad;
    const double render = trace_refracted_ray(model().shells(550.0), kR, zenith, false).bending_rad;
    const double tolerance_arcsec = zenith == 90.0 ? 1.0 : 0.1;
    EXPECT_NEAR(render * kRadToDeg * 3600.0, reference * kRadToDeg * 3600.0, tolerance_arcsec) << zenith;
  }
  EXPECT_LT(model().shells(550.0).shell_count(), 260);
}

// The bent path's points lie on the curved ray: its end leaves the top along
// the tracer's exit direction, and every chord joins consecutive points.
TEST(AtmosphereRefraction, BentPathFollowsTheTracedRay) {
  const glm::dvec3 o(0.0, 0.0, kR + 10.0);
  const glm::dvec3 d = glm::normalize(glm::dvec3(0.0, 1.0, 0.001));
  BentPath path;
  model().trace(o, d, 550.0, &path);
  ASSERT_EQ(path.outcome, RefractedRay::Outcome::kEscaped);
  ASSERT_TRUE(path.in_atmosphere);
  EXPECT_EQ(path.t_enter, 0.0);
  const Chord& last = path.chords.back();
  EXPECT_NEAR(glm::length(last.o + last.length * last.d), kR + 100000.0, 1e-3);
  for (std::size_t i = 1; i < path.chords.size(); ++i) {
    const Chord& a = path.chords[i - 1];
    EXPECT_LT(glm::length(a.o + a.length * a.d - path.chords[i].o), 1e-6);
    EXPECT_NEAR(a.t0 + a.length, path.chords[i].t0, 1e-6);
  }
  // The ray rose: the exit direction is bent downwards (towards the planet) from the start's.
  const double bending = std::acos(glm::dot(path.exit_direction, d)) * kRadToDeg * 60.0;
  EXPECT_GT(bending, 25.0);
  EXPECT_LT(bending, 40.0);
}

// apparent_elevation inverts true_elevation; the solid-angle ratio is the
// flattening: ~1 high up, < 1 near the horizon (cos e_a de_a over cos e_t de_t).
TEST(AtmosphereRefraction, ElevationMapsInvertEachOther) {
  for (const double h : {0.0, 120.0, 2500.0, 30000.0}) {
    for (const double e_true : {-1.0, -0.5, 0.0, 2.0, 20.0, 70.0}) {
      const auto e_app = model().apparent_elevation_deg(h, e_true, 550.0);
      if (!e_app) {
        EXPECT_LT(e_true, 0.0) << h;
        continue;
      }
      EXPECT_GT(*e_app, e_true);
      EXPECT_NEAR(*model().true_elevation_deg(h, *e_app, 550.0), e_true, 1e-7);
    }
  }
  EXPECT_NEAR(model().solid_angle_ratio(0.0, 60.0, 550.0), 1.0, 1e-3);
  const double flat = model().solid_angle_ratio(0.0, 0.05, 550.0);
  EXPECT_GT(flat, 0.7);
  EXPECT_LT(flat, 0.9);
}

}  // namespace
}  // namespace skyfarm

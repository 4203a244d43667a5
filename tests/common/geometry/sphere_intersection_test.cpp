// Ray / sphere intersection exactness at planetary scale (a camera
// 1 m above a 6 371 km planet exact to millimetres; grazing rays must not flip
// between hit and miss).  Expected values are closed-form distances computed
// from the altitude, not from |o|^2 - R^2.
#include "common/geometry/sphere_intersection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double R = 6371000.0;

Ray ray_from_altitude(double h, double zenith_rad) {
  return {{0.0, 0.0, R + h}, direction_from_zenith_azimuth(zenith_rad, 0.3)};
}

TEST(SphereIntersection, OneMetreAboveGroundLookingDown) {
  const Ray ray{{0.0, 0.0, R + 1.0}, {0.0, 0.0, -1.0}};
  const auto hit = intersect_sphere(ray, R);
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.t_near, 1.0, 1e-9);
  EXPECT_NEAR(hit.t_far, 2.0 * R + 1.0, 1e-6);
  EXPECT_NEAR(altitude_above(ray.at(hit.t_near), R), 0.0, 1e-9);
}

TEST(SphereIntersection, OneMetreAboveGroundObliqueIsExactToMillimetres) {
  // From radius r = R + h at zenith cosine mu < mu_horizon the ground is at
  // t = -r mu - sqrt(r^2 mu^2 - (r^2 - R^2)), with r^2 - R^2 = h (2R + h).
  // Rewritten without cancellation: t = h (2R + h) / (-r mu + sqrt(r^2 mu^2 - h (2R + h))).
  const double h = 1.0, r = R + h;
  for (double zenith_deg : {100.0, 95.0, 91.0, 90.1, 90.05}) {
    const double mu = std::cos(zenith_deg * kDegToRad);
    const double c = h * (2.0 * R + h);
    const double t_expected = c / (-r * mu + std::sqrt(r * r * mu * mu - c));
    const Ray ray = ray_from_altitude(h, zenith_deg * kDegToRad);
    const double t = distance_to_sphere(ray, R);
    EXPECT_NEAR(t, t_expected, 1e-3) << zenith_deg;
    EXPECT_NEAR(altitude_above(ray.at(t), R), 0.0, 1e-3) << zenith_deg;
  }
}

TEST(SphereIntersection, HorizontalRayMissesAndReachesTheHorizonDistance) {
  // A horizontal ray from h never meets the ground; it reaches the top of the
  // atmosphere at sqrt((R_top - r)(R_top + r)) = sqrt(R_top^2 - r^2).
  const double h = 1.0, top = R + 100000.0;
  const Ray ray = ray_from_altitude(h, kPi / 2.0);
  EXPECT_LT(distance_to_sphere(ray, R), 0.0);
  const double expected = std::sqrt((top - (R + h)) * (top + (R + h)));
  EXPECT_NEAR(distance_to_sphere(ray, top), expected, 1e-6);
}

TEST(SphereIntersection, GrazingRaysDoNotFlipBetweenHitAndMiss) {
  // Sweep the zenith angle through the horizon of a camera at 1 m, 2 km and
  // 400 km in steps of 1e-10 rad: the ground must be hit below the horizon and
  // missed above, switching exactly once.
  for (double h : {1.0, 2000.0, 400000.0}) {
    const double r = R + h;
    const double zenith_h = std::acos(horizon_cosine(r, R));
    int switches = 0;
    bool prev_hit = true;
    for (int k = -2000; k <= 2000; ++k) {
      const double z = zenith_h - k * 1e-10;
      const bool hit = distance_to_sphere(ray_from_altitude(h, z), R) > 0.0;
      if (k == -2000) {
        EXPECT_TRUE(hit) << h;  // below the horizon
      }
      if (k == 2000) {
        EXPECT_FALSE(hit) << h;  // above it
      }
      if (k > -2000 && hit != prev_hit) ++switches;
      prev_hit = hit;
    }
    EXPECT_EQ(switches, 1) << "altitude " << h;
  }
}

TEST(SphereIntersection, GrazingHitDistanceIsContinuous) {
  // Just below the horizon the two ground roots merge at the tangent distance
  // sqrt(r^2 - R^2); the near root must approach it smoothly.
  const double h = 2000.0, r = R + h;
  const double zenith_h = std::acos(horizon_cosine(r, R));
  const double tangent = std::sqrt((r - R) * (r + R));
  for (double eps : {1e-6, 1e-8, 1e-10}) {
    const double t = distance_to_sphere(ray_from_altitude(h, zenith_h + eps), R);
    ASSERT_GT(t, 0.0);
    EXPECT_NEAR(t, tangent, 0.05 * tangent) << eps;
  }
}

TEST(SphereIntersection, InsideSphereFindsTheExit) {
  const Ray ray{{0.0, 0.0, R + 10.0}, {0.0, 0.0, 1.0}};
  EXPECT_NEAR(distance_to_sphere(ray, R + 100000.0), 99990.0, 1e-8);
  // From geostationary orbit looking at the planet's centre.
  const Ray geo{{0.0, 0.0, R + 35786000.0}, {0.0, 0.0, -1.0}};
  EXPECT_NEAR(distance_to_sphere(geo, R + 100000.0), 35686000.0, 1e-6);
  EXPECT_NEAR(distance_to_sphere(geo, R), 35786000.0, 1e-6);
}

TEST(RayDirections, ZenithAzimuthRoundTrip) {
  // Azimuth clockwise from north (+y) towards east (+x).
  const auto east = direction_from_zenith_azimuth(kPi / 2.0, kPi / 2.0);
  EXPECT_NEAR(east.x, 1.0, 1e-15);
  EXPECT_NEAR(east.y, 0.0, 1e-15);
  for (double z = 0.01; z < kPi; z += 0.37)
    for (double a = 0.0; a < 2.0 * kPi; a += 0.41) {
      double z2 = 0.0, a2 = 0.0;
      zenith_azimuth_from_direction(direction_from_zenith_azimuth(z, a), &z2, &a2);
      EXPECT_NEAR(z2, z, 1e-13);
      EXPECT_NEAR(a2, a, 1e-13);
    }
}

}  // namespace
}  // namespace skyfarm

namespace skyfarm {
namespace {

TEST(SphereIntersection, CameraOnTheGroundSeesTheGroundAtItsFeet) {
  // At altitude 0 a downward ray meets the ground at once, not on the far side.
  const Ray down{{0.0, 0.0, R}, direction_from_zenith_azimuth(120.0 * kDegToRad, 0.0)};
  EXPECT_EQ(ground_distance(down, R), 0.0);
  const Ray up{{0.0, 0.0, R}, direction_from_zenith_azimuth(60.0 * kDegToRad, 0.0)};
  EXPECT_LT(ground_distance(up, R), 0.0);
  const Ray above{{0.0, 0.0, R + 10.0}, {0.0, 0.0, -1.0}};
  EXPECT_NEAR(ground_distance(above, R), 10.0, 1e-9);
}

}  // namespace
}  // namespace skyfarm

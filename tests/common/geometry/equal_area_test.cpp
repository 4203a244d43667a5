// The equal-area octahedral mapping (common/geometry/equal_area.h): known
// points, round trips both ways, and equal solid angle per pixel measured
// independently (spherical triangles over a fine subdivision of each pixel).
#include "common/geometry/equal_area.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

namespace skyfarm {
namespace {

constexpr double kFourPi = 4.0 * M_PI;

void expect_direction(const glm::dvec3& got, const glm::dvec3& want, double tol = 1e-12) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(EqualArea, KnownPoints) {
  // Centre = +z, corners = -z, the diamond's vertices = the four horizon axes.
  expect_direction(equal_area_square_to_sphere({0.5, 0.5}), {0, 0, 1});
  for (auto corner : {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(1, 1)})
    expect_direction(equal_area_square_to_sphere(corner), {0, 0, -1});
  expect_direction(equal_area_square_to_sphere({1.0, 0.5}), {1, 0, 0});
  expect_direction(equal_area_square_to_sphere({0.0, 0.5}), {-1, 0, 0});
  expect_direction(equal_area_square_to_sphere({0.5, 1.0}), {0, 1, 0});
  expect_direction(equal_area_square_to_sphere({0.5, 0.0}), {0, -1, 0});
  // Halfway from the centre to an edge's midpoint: r = 1/2, so z = 1 - r^2 = 3/4.
  expect_direction(equal_area_square_to_sphere({0.75, 0.5}), {std::sqrt(1 - 0.75 * 0.75), 0, 0.75});
  // The diamond's edge midpoint (u = v = 1/2) is on the equator at azimuth 45 deg.
  expect_direction(equal_area_square_to_sphere({0.75, 0.75}), {M_SQRT1_2, M_SQRT1_2, 0});
  const glm::dvec2 p = equal_area_sphere_to_square({0, 0, -1});
  EXPECT_NEAR(std::min(p.x, 1 - p.x), 0.0, 1e-12);  // a corner
  EXPECT_NEAR(std::min(p.y, 1 - p.y), 0.0, 1e-12);
}

TEST(EqualArea, SquareToSphereToSquareRoundTrips) {
  // Every point of a 65 x 65 grid but the corners (all four are -z) and the
  // edges' mirror pairs (the square's boundary folds onto itself).
  for (int i = 1; i < 64; ++i)
    for (int j = 1; j < 64; ++j) {
      const glm::dvec2 p(i / 64.0, j / 64.0);
      const glm::dvec3 d = equal_area_square_to_sphere(p);
      EXPECT_NEAR(glm::length(d), 1.0, 1e-14);
      const glm::dvec2 q = equal_area_sphere_to_square(d);
      EXPECT_NEAR(q.x, p.x, 1e-12) << i << "," << j;
      EXPECT_NEAR(q.y, p.y, 1e-12) << i << "," << j;
    }
}

TEST(EqualArea, SphereToSquareToSphereRoundTrips) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  for (int k = 0; k < 10000; ++k) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    const glm::dvec2 p = equal_area_sphere_to_square(d);
    ASSERT_GE(p.x, 0.0);
    ASSERT_LE(p.x, 1.0);
    ASSERT_GE(p.y, 0.0);
    ASSERT_LE(p.y, 1.0);
    expect_direction(equal_area_square_to_sphere(p), d, 1e-12);
  }
}

// Solid angle of the spherical triangle a, b, c (unit vectors): Van Oosterom
// and Strackee (1983), tan(E/2) = |a . (b x c)| / (1 + a.b + b.c + c.a).
double triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double num = std::abs(glm::dot(a, glm::cross(b, c)));
  const double den = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  return 2.0 * std::atan2(num, den);
}

// The solid angle of the square region [x0, x1] x [y0, y1], its image cut
// into sub x sub quads, each two spherical triangles (the pixel's edges are
// not great circles: the error falls as 1/sub^2).
double region_solid_angle(double x0, double y0, double x1, double y1, int sub) {
  double sum = 0.0;
  for (int i = 0; i < sub; ++i)
    for (int j = 0; j < sub; ++j) {
      const double sa = x0 + (x1 - x0) * i / sub, sb = x0 + (x1 - x0) * (i + 1) / sub;
      const double ta = y0 + (y1 - y0) * j / sub, tb = y0 + (y1 - y0) * (j + 1) / sub;
      const glm::dvec3 p00 = equal_area_square_to_sphere({sa, ta}), p10 = equal_area_square_to_sphere({sb, ta});
      const glm::dvec3 p01 = equal_area_square_to_sphere({sa, tb}), p11 = equal_area_square_to_sphere({sb, tb});
      sum += triangle_solid_angle(p00, p10, p11) + triangle_solid_angle(p00, p11, p01);
    }
  return sum;
}

TEST(EqualArea, EveryPixelHoldsTheSameSolidAngle) {
  // An 8 x 8 map: pixels at the poles, on the equator's folds and across the
  // diamond's edges (where the mapping bends) all hold 4 pi / 64 sr.
  constexpr int n = 8;
  const double want = equal_area_pixel_solid_angle(n);
  EXPECT_DOUBLE_EQ(want, kFourPi / 64.0);
  double total = 0.0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double omega = region_solid_angle(double(x) / n, double(y) / n, double(x + 1) / n, double(y + 1) / n, 48);
      EXPECT_NEAR(omega, want, 2e-4 * want) << x << "," << y;
      total += omega;
    }
  EXPECT_NEAR(total, kFourPi, 1e-4 * kFourPi);
  // A region off the pixel grid too: the area fraction is kept anywhere.
  const double omega = region_solid_angle(0.1, 0.3, 0.37, 0.52, 48);
  EXPECT_NEAR(omega, kFourPi * 0.27 * 0.22, 2e-4 * omega);
}

}  // namespace
}  // namespace skyfarm

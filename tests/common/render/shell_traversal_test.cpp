// The shell walk covers a ray's extent with contiguous segments, each lying
// in the shell it names, for rays from the ground, the air and orbit.
#include "common/render/shell_traversal.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <random>

#include "common/atmosphere/majorant_grid.h"
#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm {
namespace {

constexpr double R = 6371000.0;

void check_walk(const Ray& ray, const std::vector<double>& h) {
  const double top = R + h.back();
  const SphereHit top_hit = intersect_sphere(ray, top);
  if (!top_hit.hit || top_hit.t_far <= 0.0) return;
  const double t_begin = std::max(0.0, top_hit.t_near);
  double t_end = top_hit.t_far;
  const double t_ground = ground_distance(ray, R);
  if (t_ground >= 0.0) t_end = t_ground;
  ShellTraversal walk(ray, R, h, t_begin, t_end);
  ShellSegment seg;
  double t = t_begin;
  std::size_t prev_shell = 0;
  int count = 0;
  while (walk.next(&seg)) {
    ASSERT_DOUBLE_EQ(seg.t0, t) << "segments must be contiguous";
    ASSERT_GE(seg.t1, seg.t0);
    if (count > 0) {
      ASSERT_LE(std::abs(static_cast<long>(seg.shell) - static_cast<long>(prev_shell)), 1);
    }
    if (seg.t1 - seg.t0 > 1e-3) {
      // Altitude anywhere inside the segment lies in the named shell.
      for (double f : {0.001, 0.5, 0.999}) {
        const double alt = glm::length(ray.at(seg.t0 + f * (seg.t1 - seg.t0))) - R;
        ASSERT_GE(alt, h[seg.shell] - 1e-6) << "shell " << seg.shell;
        ASSERT_LE(alt, h[seg.shell + 1] + 1e-6) << "shell " << seg.shell;
      }
    }
    t = seg.t1;
    prev_shell = seg.shell;
    ++count;
  }
  EXPECT_DOUBLE_EQ(t, t_end);
}

TEST(ShellTraversal, CoversRaysFromGroundAirAndOrbit) {
  const auto h = majorant_shell_boundaries(100000.0);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (double altitude : {0.0, 1.0, 1500.0, 12000.0, 99999.0, 400000.0, 35786000.0}) {
    for (int i = 0; i < 300; ++i) {
      const double zenith = std::acos(1.0 - 2.0 * U(rng));
      const Ray ray{{0.0, 0.0, R + altitude}, direction_from_zenith_azimuth(zenith, 2.0 * kPi * U(rng))};
      check_walk(ray, h);
    }
    // Horizontal and grazing rays.
    for (double z : {90.0, 90.5, 95.0})
      check_walk(Ray{{0.0, 0.0, R + altitude}, direction_from_zenith_azimuth(z * kDegToRad, 0.3)}, h);
  }
}

TEST(ShellTraversal, StraightDownFromTheTopVisitsEveryShellOnce) {
  const auto h = majorant_shell_boundaries(100000.0);
  const Ray ray{{0.0, 0.0, R + 100000.0}, {0.0, 0.0, -1.0}};
  ShellTraversal walk(ray, R, h, 0.0, 100000.0);
  ShellSegment seg;
  std::size_t expected = h.size() - 2;
  while (walk.next(&seg)) {
    EXPECT_EQ(seg.shell, expected);
    EXPECT_NEAR(seg.t1 - seg.t0, h[expected + 1] - h[expected], 1e-6);
    if (expected == 0) break;
    --expected;
  }
  EXPECT_EQ(expected, 0u);
}

}  // namespace
}  // namespace skyfarm

// A recorded shell walk replays exactly the walk's segments, also past its
// capacity; an empty one (and an empty ShellTraversal) yields nothing, and a
// record made in place of an empty one is the same as one constructed.
#include "common/render/recorded_shell_walk.h"

#include <gtest/gtest.h>

#include <vector>

#include "common/atmosphere/majorant_grid.h"
#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm {
namespace {

constexpr double R = 6371000.0;

template <class Walk>
std::vector<ShellSegment> segments_of(Walk walk) {
  std::vector<ShellSegment> out;
  ShellSegment s;
  while (walk.next(&s)) out.push_back(s);
  return out;
}

void expect_same(const std::vector<ShellSegment>& a, const std::vector<ShellSegment>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t0, b[i].t0);
    EXPECT_EQ(a[i].t1, b[i].t1);
    EXPECT_EQ(a[i].shell, b[i].shell);
  }
}

TEST(RecordedShellWalk, EmptyWalksYieldNothing) {
  EXPECT_TRUE(segments_of(ShellTraversal()).empty());
  const RecordedShellWalk none;
  EXPECT_FALSE(none.recorded());
  EXPECT_TRUE(segments_of(none.replay()).empty());
}

TEST(RecordedShellWalk, ReplaysTheWalkBitForBit) {
  const auto h = majorant_shell_boundaries(100000.0);
  // A ray from 90 km going down to about 27 km and up again crosses most shells twice.
  const Ray ray{{0.0, 0.0, R + 90000.0}, direction_from_zenith_azimuth(98.0 * kDegToRad, 0.3)};
  const SphereHit top = intersect_sphere(ray, R + 100000.0);
  ASSERT_TRUE(top.hit);
  const ShellTraversal walk(ray, R, h, 0.0, top.t_far);
  const std::vector<ShellSegment> want = segments_of(walk);
  ASSERT_GT(want.size(), 20u) << "the ray should cross many shells";
  const RecordedShellWalk constructed(walk);
  EXPECT_TRUE(constructed.recorded());
  expect_same(segments_of(constructed.replay()), want);
  expect_same(segments_of(constructed.replay()), want);  // again
  RecordedShellWalk in_place;
  in_place.record(ShellTraversal(ray, R, h, 0.0, 1.0e5));  // replaced below
  in_place.record(walk);
  EXPECT_TRUE(in_place.recorded());
  expect_same(segments_of(in_place.replay()), want);
}

TEST(RecordedShellWalk, AWalkLongerThanTheRecordIsReplayedWhole) {
  // More boundaries than the record holds: a straight-down ray crosses each.
  std::vector<double> h;
  for (int i = 0; i <= 400; ++i) h.push_back(250.0 * i);
  const Ray ray{{0.0, 0.0, R + 100000.0}, {0.0, 0.0, -1.0}};
  const ShellTraversal walk(ray, R, h, 0.0, 100000.0);
  const std::vector<ShellSegment> want = segments_of(walk);
  ASSERT_GT(want.size(), RecordedShellWalk::kCapacity);
  RecordedShellWalk record;
  record.record(walk);
  expect_same(segments_of(record.replay()), want);
  expect_same(segments_of(record.replay()), want);
}

}  // namespace
}  // namespace skyfarm

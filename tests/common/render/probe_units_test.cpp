// A probe cut into units (common/render/probe_units.h): the cut covers every
// (pair, sample) once and stays bounded, the sums survive the wire, and the
// reduction is the same bits whatever order the units arrive in and however
// many threads traced them.
#include "common/render/probe_units.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "tests/support/sun_specs.h"

namespace skyfarm {
namespace {

glm::dvec3 dir(double zenith_deg, double azimuth_deg) {
  return direction_from_zenith_azimuth(zenith_deg * kDegToRad, azimuth_deg * kDegToRad);
}

// Every (pair, sample) of the plan is in exactly one unit.
void expect_exact_cover(const ProbePlan& plan) {
  std::vector<std::uint64_t> covered(plan.pairs, 0);  // samples per pair, summed over units
  std::set<std::pair<std::size_t, std::uint64_t>> starts;
  for (std::size_t i = 0; i < plan.unit_count(); ++i) {
    const ProbeUnit u = plan.unit(i);
    EXPECT_EQ(u.index, i);
    ASSERT_LT(u.pair_begin, u.pair_end);
    ASSERT_LE(u.pair_end, plan.pairs);
    ASSERT_LT(u.sample_begin, u.sample_end);
    ASSERT_LE(u.sample_end, plan.samples);
    for (std::size_t p = u.pair_begin; p < u.pair_end; ++p) {
      EXPECT_TRUE(starts.emplace(p, u.sample_begin).second) << "pair " << p << " sample " << u.sample_begin;
      covered[p] += u.sample_end - u.sample_begin;
    }
  }
  for (std::size_t p = 0; p < plan.pairs; ++p) EXPECT_EQ(covered[p], plan.samples) << "pair " << p;
}

TEST(ProbePlan, CoversEverySampleOnceAndStaysBounded) {
  struct Case {
    std::size_t pairs;
    std::uint64_t samples;
  };
  for (const Case c : {Case{1, 1}, Case{3, 4096}, Case{1, 1000000}, Case{3, 65537}, Case{7, 200000}, Case{1000, 10},
                       Case{100000, 10000}, Case{1, 1000000000}}) {
    const ProbePlan plan = ProbePlan::make(c.pairs, c.samples);
    SCOPED_TRACE(std::to_string(c.pairs) + " pairs x " + std::to_string(c.samples) + " samples");
    EXPECT_LE(plan.unit_count(), 2 * kProbeDefaultMaxUnits + 1);
    if (plan.unit_count() < 20000) expect_exact_cover(plan);
    EXPECT_THROW(plan.unit(plan.unit_count()), std::out_of_range);
  }
  // Small probes are one unit; a long one is cut along its samples.
  EXPECT_EQ(ProbePlan::make(3, 4096).unit_count(), 1u);
  const ProbePlan long_one = ProbePlan::make(1, 1000000);
  EXPECT_EQ(long_one.pairs_per_unit, 1u);
  EXPECT_EQ(long_one.chunk_samples, kProbeMinUnitPaths);
  EXPECT_EQ(long_one.chunks, 16u);
  // The first chunk of every pair is handed out first.
  const ProbePlan wide = ProbePlan::make(4, 200000);
  EXPECT_EQ(wide.unit(0).pair_begin, 0u);
  EXPECT_EQ(wide.unit(3).pair_begin, 3u);
  EXPECT_EQ(wide.unit(3).sample_begin, 0u);
  EXPECT_EQ(wide.unit(4).sample_begin, wide.chunk_samples);
  EXPECT_THROW(ProbePlan::make(0, 10), std::invalid_argument);
  EXPECT_THROW(ProbePlan::make(1, 0), std::invalid_argument);
}

TEST(ProbeUnitSums, RoundTripsAndRejectsWhatItCannotBe) {
  const ProbePlan plan = ProbePlan::make(5, 300, kProbeDefaultMaxUnits, 400);  // 1 pair x 300 samples per unit
  ProbeUnitSums s;
  s.unit = plan.unit(plan.unit_count() - 1);
  for (std::size_t p = s.unit.pair_begin; p < s.unit.pair_end; ++p) {
    s.sum.push_back(0.1 * static_cast<double>(p) + 1e-300);
    s.sum_sq.push_back(0.3 * static_cast<double>(p));
  }
  s.counters.paths = 12345;
  s.counters.nonfinite = 2;
  const std::vector<std::uint8_t> bytes = s.serialize();
  const ProbeUnitSums back = ProbeUnitSums::deserialize(bytes, plan);
  EXPECT_EQ(back.unit, s.unit);
  EXPECT_EQ(back.sum, s.sum);
  EXPECT_EQ(back.sum_sq, s.sum_sq);
  EXPECT_EQ(back.counters.paths, 12345u);
  EXPECT_EQ(back.counters.nonfinite, 2u);

  auto broken = [&](auto edit) {
    std::vector<std::uint8_t> b = bytes;
    edit(b);
    return b;
  };
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b.resize(40); }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b.pop_back(); }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b[0] = 'X'; }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b[4] = 9; }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b[8] = 0xff; }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b[32] ^= 1; }), plan), ProbeUnitDecodeError);
  EXPECT_THROW(ProbeUnitSums::deserialize(broken([](auto& b) { b[64 + 7] = 0xff; }), plan),  // a NaN sum
               ProbeUnitDecodeError);
  // Another probe's plan: its unit of that index has other samples.
  EXPECT_THROW(ProbeUnitSums::deserialize(bytes, ProbePlan::make(5, 600, kProbeDefaultMaxUnits, 400)),
               ProbeUnitDecodeError);
}

class ProbeReductionTest : public ::testing::Test {
 protected:
  ProbeReductionTest()
      : scene_(Scene::from_specs(AtmosphereSpec{}, testing::sun_spec(40.0, 120.0), Location{}, std::nullopt, 449.5,
                                 650.5)) {}
  const Scene scene_;
  const std::vector<glm::dvec3> dirs_ = {dir(0.0, 0.0), dir(75.0, 300.0), dir(100.0, 10.0)};
  const std::vector<double> wavelengths_ = {450.0, 650.0};
};

// Units traced one by one (as farm workers do) and added in a shuffled
// order give the bits of probe_radiance on 1 or 3 threads.
TEST_F(ProbeReductionTest, AnyOrderAndAnyThreadCountGiveTheSameBits) {
  const ProbePlan plan = ProbePlan::make(6, 700, kProbeDefaultMaxUnits, 1000);  // 1 pair x 700 samples per unit
  ASSERT_EQ(plan.unit_count(), 6u);
  const ProbePlan chunked = ProbePlan::make(6, 700, kProbeDefaultMaxUnits, 300);  // chunks of 300 samples
  ASSERT_EQ(chunked.chunks, 3u);
  for (const ProbePlan& p : {plan, chunked}) {
    const ProbeResult local1 = probe_radiance(scene_, dirs_, wavelengths_, p, 7, 1);
    const ProbeResult local3 = probe_radiance(scene_, dirs_, wavelengths_, p, 7, 3);
    std::vector<std::size_t> order(p.unit_count());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), std::mt19937(5));
    ProbeReduction farm(p);
    for (const std::size_t i : order) {
      EXPECT_FALSE(farm.complete());
      const auto bytes = trace_probe_unit(scene_, dirs_, wavelengths_, 7, p.unit(i)).serialize();
      EXPECT_TRUE(farm.add(ProbeUnitSums::deserialize(bytes, p)));
    }
    ASSERT_TRUE(farm.complete());
    EXPECT_FALSE(farm.add(trace_probe_unit(scene_, dirs_, wavelengths_, 7, p.unit(0)))) << "a repeat is ignored";
    const ProbeResult r = farm.result(2);
    EXPECT_EQ(r.radiance, local1.radiance);
    EXPECT_EQ(r.standard_error, local1.standard_error);
    EXPECT_EQ(local3.radiance, local1.radiance);
    EXPECT_EQ(local3.standard_error, local1.standard_error);
    EXPECT_EQ(r.counters.paths, 6u * 700u);
    for (const auto& row : r.radiance)
      for (double L : row) EXPECT_GT(L, 0.0);
  }
  // The cut changes only the order of the additions: the same estimates, to rounding.
  const ProbeResult a = probe_radiance(scene_, dirs_, wavelengths_, plan, 7, 2);
  const ProbeResult b = probe_radiance(scene_, dirs_, wavelengths_, chunked, 7, 2);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t w = 0; w < 2; ++w) EXPECT_NEAR(a.radiance[d][w], b.radiance[d][w], 1e-12 * a.radiance[d][w]);
}

TEST_F(ProbeReductionTest, RefusesForeignUnitsAndAnswersOnlyWhenComplete) {
  const ProbePlan plan = ProbePlan::make(6, 50, kProbeDefaultMaxUnits, 100);  // 2 pairs per unit
  ProbeReduction reduction(plan);
  EXPECT_THROW(reduction.result(2), std::logic_error);
  ProbeUnitSums wrong = trace_probe_unit(scene_, dirs_, wavelengths_, 1, plan.unit(0));
  wrong.sum.pop_back();
  EXPECT_THROW(reduction.add(wrong), std::invalid_argument);
  wrong = trace_probe_unit(scene_, dirs_, wavelengths_, 1, plan.unit(0));
  wrong.unit.sample_end = 49;
  EXPECT_THROW(reduction.add(wrong), std::invalid_argument);
  EXPECT_EQ(reduction.received(), 0u);
}

}  // namespace
}  // namespace skyfarm

#include "server/tools/farm_sim.h"

#include <gtest/gtest.h>

namespace skyfarm::server {
namespace {

// The scale benchmark's simulation, small: every unit reaches a simulated
// worker, comes back as a valid result and is merged, and every job ends done.
// No timing is asserted (speed is the benchmark's business).
TEST(FarmSim, TwentyWorkersCompleteTwoThousandUnits) {
  FarmSimOptions o;
  o.workers = 20;
  o.units = 2000;
  o.jobs = 2;
  o.timeout_s = 120.0;
  const FarmSimResult r = run_farm_sim(o);
  ASSERT_EQ(r.jobs.size(), 2u);
  // 1000 units a job: 16 passes of 64 batches of one pixel, rounded up to 1024.
  EXPECT_EQ(r.units_expected, 2048);
  for (const auto& job : r.jobs) {
    EXPECT_EQ(job.state, "done") << job.id;
    EXPECT_EQ(job.units_total, 1024) << job.id;
    EXPECT_EQ(job.units_done, 1024) << job.id;
  }
  EXPECT_TRUE(r.all_done);
  EXPECT_GE(r.results_sent, r.units_expected);
  EXPECT_EQ(r.broker.malformed, 0u);
  EXPECT_EQ(r.broker.backend_errors, 0u);
}

TEST(FarmSim, RefusesBadOptions) {
  FarmSimOptions o;
  o.workers = 0;
  EXPECT_THROW(run_farm_sim(o), std::runtime_error);
  o.workers = 2;
  o.units = 1;
  o.jobs = 2;
  EXPECT_THROW(run_farm_sim(o), std::runtime_error);
}

}  // namespace
}  // namespace skyfarm::server

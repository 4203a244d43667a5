// ProbeRouter (server/probes/probe_router.h): probe units go ahead of render units,
// three of every four while both have work (renders are never starved);
// results and failures reach whichever service owns the attempt; joins,
// losses, timeouts and cancels reach both.
#include "server/probes/probe_router.h"

#include <gtest/gtest.h>

#include <future>

#include "tests/server/broker/fake_broker_backend.h"
#include "tests/server/probes/probe_workers.h"

namespace skyfarm::server {
namespace {

using namespace std::chrono_literals;

api::ProbeRequest big_probe() {  // 1 x 3 x 300000: 15 units
  return api::parse_probe_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 150},
      "directions": [{"zenith_deg": 20, "azimuth_deg": 0}], "wavelengths_nm": [450, 550, 650], "samples": 300000})");
}

class ProbeRouterTest : public ::testing::Test {
 protected:
  ProbeRouterTest() : router_(probes_, renders_) {
    renders_.add_units("render-1", 4, 2, 2, skyfarm::testing::tiny_request());  // 16 render units
    router_.worker_joined("w", skyfarm::testing::worker_info("w"));
  }
  ~ProbeRouterTest() override {
    probes_.close();
    if (answer_.valid()) answer_.wait();
  }
  void submit_probe() {
    answer_ = std::async(std::launch::async, [this] { return probes_.run(big_probe(), 60s); });
    ASSERT_TRUE(skyfarm::testing::eventually_true([&] { return probes_.stats().active == 1; }));
  }

  ProbeService probes_;
  skyfarm::testing::FakeBackend renders_;
  ProbeRouter router_;
  std::future<nlohmann::json> answer_;
};

TEST_F(ProbeRouterTest, ProbesGoFirstThreeInFourAndRendersAreNotStarved) {
  EXPECT_EQ(renders_.with_lock([](auto& b) { return b.joined.size(); }), 1u) << "joins reach the renders";
  EXPECT_EQ(probes_.stats().workers, 1u) << "and the probes";
  // Renders alone: renders.
  ASSERT_TRUE(router_.next_unit("w"));
  submit_probe();
  std::string kinds;
  for (int i = 0; i < 12; ++i) {
    const auto u = router_.next_unit("w");
    ASSERT_TRUE(u);
    kinds += u->kind == api::UnitKind::kProbe ? 'P' : 'R';
    EXPECT_EQ(is_probe_attempt(u->attempt), u->kind == api::UnitKind::kProbe);
  }
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), 'P'), 9) << kinds;
  EXPECT_EQ(std::count(kinds.begin(), kinds.end(), 'R'), 3) << kinds;
}

TEST_F(ProbeRouterTest, ResultsReachTheServiceThatOwnsTheAttempt) {
  submit_probe();
  std::optional<UnitAssignment> probe_unit, render_unit;
  while (!probe_unit || !render_unit) {
    auto u = router_.next_unit("w");
    ASSERT_TRUE(u);
    (u->kind == api::UnitKind::kProbe ? probe_unit : render_unit) = u;
  }
  router_.unit_done("w", render_unit->key, render_unit->attempt, {9}, 1);
  router_.unit_failed("w", probe_unit->key, probe_unit->attempt, "boom");
  EXPECT_EQ(renders_.with_lock([](auto& b) { return b.done.size(); }), 1u);
  EXPECT_EQ(renders_.with_lock([](auto& b) { return b.failed.size(); }), 0u);
  EXPECT_EQ(probes_.stats().unit_failures, 1u);
  // Timeouts and losses reach both: the probe's units come back.
  router_.check_timeouts(Clock::now() + 1h);
  router_.worker_left("w");
  EXPECT_EQ(renders_.with_lock([](auto& b) { return b.left.size(); }), 1u);
  EXPECT_EQ(probes_.stats().workers, 0u);
  EXPECT_EQ(probes_.stats().units_in_flight, 0u);
  renders_.cancel(render_unit->attempt);  // nothing to cancel: it is done
  probes_.close();
  EXPECT_FALSE(router_.take_cancelled_attempts().empty()) << "the timed-out probe units were cancelled";
}

}  // namespace
}  // namespace skyfarm::server

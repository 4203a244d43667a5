// ProbeService (server/probes/probe_service.h) driven in process through its
// BrokerBackend side: the answer is the local probe's document, number for
// number, whatever the number of workers and the order of the results; lost
// workers, failing workers and unreadable results are survived or reported
// with the workers' message; no worker -> NoProbeWorkers; a late probe ->
// ProbeTimedOut with its units cancelled.  Probes here are 4 units of
// ~35000 paths (kProbeMinUnitPaths bounds how small a unit is).
#include "server/probes/probe_service.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <future>

#include "api/probe_answer.h"
#include "api/probe_spec.h"
#include "tests/server/probes/probe_workers.h"

namespace skyfarm::server {
namespace {

using namespace std::chrono_literals;
using testing::ProbeWorker;
using testing::ProbeWorkerMode;

// 1 direction x 2 wavelengths x 70000 samples: 2 chunks per pair, 4 units.
api::ProbeRequest four_unit_probe(std::uint64_t seed = 3) {
  return api::parse_probe_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 150},
      "atmosphere": {"preset": "earth_clear"}, "directions": [{"zenith_deg": 20, "azimuth_deg": 0}],
      "wavelengths_nm": [650, 700], "samples": 70000, "seed": )" + std::to_string(seed) + "}");
}

const nlohmann::json& local_answer() {
  static const nlohmann::json answer =
      api::probe_answer_json(four_unit_probe(), answer_probe(api::probe_spec(four_unit_probe()), 2));
  return answer;
}

TEST(ProbeService, TheFourUnitProbeIsFourUnits) { EXPECT_EQ(probe_plan(api::probe_spec(four_unit_probe())).unit_count(), 4u); }

TEST(ProbeService, AnswerIsTheLocalProbesWithOneOrThreeWorkers) {
  for (int n : {1, 3}) {
    ProbeService service;
    std::vector<std::unique_ptr<ProbeWorker>> workers;
    for (int i = 0; i < n; ++i) workers.push_back(std::make_unique<ProbeWorker>(service, "w" + std::to_string(i)));
    const nlohmann::json answer = service.run(four_unit_probe(), 60s);
    EXPECT_EQ(answer.dump(), local_answer().dump()) << n << " workers";
    int units = 0;
    for (const auto& w : workers) units += w->units();
    EXPECT_EQ(units, 4);
    const ProbeStats s = service.stats();
    EXPECT_EQ(s.done, 1u);
    EXPECT_EQ(s.units_done, 4u);
    EXPECT_EQ(s.active, 0u);
    EXPECT_EQ(s.paths, 140000u);
  }
}

// Results handed back in reverse order, with a duplicate: same bytes.
TEST(ProbeService, ResultOrderDoesNotMatter) {
  ProbeService service;
  service.worker_joined("collector", testing::worker_info("collector"));
  auto answer = std::async(std::launch::async, [&] { return service.run(four_unit_probe(), 60s); });
  std::vector<UnitAssignment> units;
  while (units.size() < 4)
    if (auto u = service.next_unit("collector")) units.push_back(*u);
    else std::this_thread::sleep_for(1ms);
  EXPECT_FALSE(service.next_unit("collector")) << "every unit is out";
  std::vector<std::vector<std::uint8_t>> results;
  for (const auto& u : units) {
    const api::Message m = run_probe_unit(make_probe_setup(u.request_canonical),
                                          api::UnitMsg{{u.key.job_id, u.key.tile, 0, 0, u.attempt}, "", u.kind});
    results.push_back(api::payload_bytes(std::get<api::ResultMsg>(m).film_tile));
  }
  for (std::size_t i = units.size(); i-- > 0;) {
    service.unit_done("collector", units[i].key, units[i].attempt, results[i], 1);
    if (i == 2) service.unit_done("collector", units[i].key, units[i].attempt, results[i], 1);  // dropped
  }
  EXPECT_EQ(answer.get().dump(), local_answer().dump());
}

TEST(ProbeService, NoWorkerThatRunsProbesIsNoProbeWorkers) {
  ProbeService service;
  EXPECT_THROW(service.run(four_unit_probe(), 1s), NoProbeWorkers);
  service.worker_joined("old", testing::worker_info("old", false));  // renders only
  EXPECT_THROW(service.run(four_unit_probe(), 1s), NoProbeWorkers);
  service.worker_joined("new", testing::worker_info("new"));
  service.worker_left("new");
  EXPECT_THROW(service.run(four_unit_probe(), 1s), NoProbeWorkers);
  EXPECT_EQ(service.stats().no_workers, 3u);
  api::ProbeRequest lut = four_unit_probe();
  lut.method = api::Method::kLut;
  EXPECT_THROW(service.run(lut, 1s), std::invalid_argument);
}

TEST(ProbeService, LateProbeTimesOutAndItsUnitsAreCancelled) {
  ProbeService service;
  ProbeWorker holder(service, "holder", ProbeWorkerMode::kHold);
  EXPECT_THROW(service.run(four_unit_probe(), 300ms), ProbeTimedOut);
  holder.stop();
  const auto cancelled = service.take_cancelled_attempts();
  EXPECT_EQ(cancelled.size(), static_cast<std::size_t>(holder.units()));
  EXPECT_GE(cancelled.size(), 1u);
  for (const auto& [worker, attempt] : cancelled) {
    EXPECT_EQ(worker, "holder");
    EXPECT_TRUE(is_probe_attempt(attempt));
    service.unit_done(worker, UnitKey{"probe-1", 0, 0, 0}, attempt, {1, 2}, 0);  // late: dropped
  }
  const ProbeStats s = service.stats();
  EXPECT_EQ(s.timed_out, 1u);
  EXPECT_EQ(s.active, 0u);
  EXPECT_EQ(s.units_in_flight, 0u);
}

TEST(ProbeService, UnitFailingOnThreeWorkersFailsTheProbeWithTheirMessage) {
  ProbeService service;
  std::vector<std::unique_ptr<ProbeWorker>> workers;
  for (const char* id : {"a", "b", "c"})
    workers.push_back(std::make_unique<ProbeWorker>(service, id, ProbeWorkerMode::kFail));
  try {
    service.run(four_unit_probe(), 30s);
    ADD_FAILURE() << "the probe should have failed";
  } catch (const ProbeFailed& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("failed on 3 workers"), std::string::npos) << what;
    EXPECT_NE(what.find("boom from "), std::string::npos) << what;
  }
  EXPECT_EQ(service.stats().failed, 1u);
  EXPECT_GE(service.stats().unit_failures, 3u);
}

// A failing worker, a worker whose results cannot be read and one that is
// lost with units in hand do not change the answer: others trace them.
TEST(ProbeService, BadAndLostWorkersAreSurvived) {
  ProbeService service;
  ProbeWorker failing(service, "failing", ProbeWorkerMode::kFail);
  ProbeWorker corrupt(service, "corrupt", ProbeWorkerMode::kCorrupt);
  ProbeWorker holder(service, "holder", ProbeWorkerMode::kHold);
  auto answer = std::async(std::launch::async, [&] { return service.run(four_unit_probe(), 60s); });
  ASSERT_TRUE(testing::eventually_true([&] { return holder.units() >= 1; }));
  holder.stop(/*leave=*/true);  // its units are requeued
  failing.stop();
  corrupt.stop();
  ProbeWorker good(service, "good");
  EXPECT_EQ(answer.get().dump(), local_answer().dump());
  const ProbeStats s = service.stats();
  EXPECT_GE(s.requeues, 1u);
}

TEST(ProbeService, TimedOutUnitsAreDispatchedAgain) {
  ProbeLimits limits;
  limits.unit_timeout_s = 0.05;
  ProbeService service(limits);
  service.worker_joined("slow", testing::worker_info("slow"));
  auto answer = std::async(std::launch::async, [&] { return service.run(four_unit_probe(), 60s); });
  std::optional<UnitAssignment> held;
  while (!held) held = service.next_unit("slow");
  service.check_timeouts(Clock::now() + 1s);
  EXPECT_EQ(service.take_cancelled_attempts(), (std::vector<std::pair<std::string, std::uint64_t>>{{"slow", held->attempt}}));
  ProbeWorker good(service, "good");
  EXPECT_EQ(answer.get().dump(), local_answer().dump());
  EXPECT_EQ(service.stats().requeues, 1u);
}

TEST(ProbeService, CloseAnswersWaitingProbes) {
  ProbeService service;
  ProbeWorker holder(service, "holder", ProbeWorkerMode::kHold);
  auto answer = std::async(std::launch::async, [&] { return service.run(four_unit_probe(), 60s); });
  ASSERT_TRUE(testing::eventually_true([&] { return holder.units() >= 1; }));
  service.close();
  EXPECT_THROW(answer.get(), NoProbeWorkers);
  EXPECT_THROW(service.run(four_unit_probe(), 1s), NoProbeWorkers);
}

}  // namespace
}  // namespace skyfarm::server

// The ZeroMQ broker (server/broker/broker.h) driven by raw DEALER peers over
// loopback: handshake, credit, heartbeats and expiry, REREGISTER, stale
// attempts, CANCEL, tokens, malformed input and shutdown.  Each test is
// bounded by short heartbeats (100 ms) and deadline waits.
#include "server/broker/broker.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>

#include "tests/server/broker/fake_broker_backend.h"

namespace skyfarm::server {
namespace {

using namespace std::chrono_literals;
using skyfarm::testing::eventually;
using skyfarm::testing::FakeBackend;
using skyfarm::testing::RawPeer;

BrokerOptions test_options() {
  BrokerOptions o;
  o.endpoint = "tcp://127.0.0.1:*";
  o.heartbeat_interval = 100ms;
  o.heartbeat_liveness = 3;
  o.log = [](std::string_view) {};
  return o;
}

class BrokerTest : public ::testing::Test {
 protected:
  void start(BrokerOptions o = test_options()) {
    broker_ = std::make_unique<Broker>(backend_, o);
    broker_->start();
  }
  std::unique_ptr<RawPeer> peer() { return std::make_unique<RawPeer>(ctx_, broker_->bound_endpoint()); }
  // A registered peer (READY answered).
  std::unique_ptr<RawPeer> joined_peer(const std::string& id, int slots = 1) {
    auto p = peer();
    p->send(RawPeer::ready(id, slots));
    EXPECT_TRUE(p->receive_a<api::HeartbeatMsg>().has_value()) << "no welcome heartbeat";
    return p;
  }
  void TearDown() override {
    if (broker_) broker_->stop();
  }
  // True when no UNIT reaches `p` for `d`.  The peer heart-beats every 50 ms
  // meanwhile: a silent peer is expired after 3 x 100 ms, so a plain 300 ms
  // wait raced the expiry, and lost it on a loaded machine (the unit owed
  // after the next result then never came).
  static bool no_unit_for(RawPeer& p, std::chrono::milliseconds d, api::HeartbeatMsg heartbeat = {}) {
    const auto until = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < until) {
      p.send(heartbeat);
      if (p.receive_a<api::UnitMsg>(50ms)) return false;
    }
    return true;
  }

  zmq::context_t ctx_;
  FakeBackend backend_;
  std::unique_ptr<Broker> broker_;
};

TEST_F(BrokerTest, BindsAWildcardPortAndStopsQuickly) {
  start();
  const std::string ep = broker_->bound_endpoint();
  EXPECT_EQ(ep.rfind("tcp://127.0.0.1:", 0), 0u) << ep;
  EXPECT_EQ(ep.find('*'), std::string::npos) << ep;
  const auto t0 = std::chrono::steady_clock::now();
  broker_->stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
  EXPECT_FALSE(broker_->running());
  broker_->stop();  // idempotent
}

TEST_F(BrokerTest, ReadyJoinsTheWorkerWithoutItsToken) {
  start();
  auto p = peer();
  api::ReadyMsg r = RawPeer::ready("w1", 3);
  r.token = "anything";  // no longer a credential: ignored
  p->send(r);
  ASSERT_TRUE(p->receive_a<api::HeartbeatMsg>());
  ASSERT_TRUE(backend_.wait_for([](auto& b) { return b.joined.size() == 1; }));
  backend_.with_lock([](auto& b) {
    const auto& [id, info] = b.joined[0];
    EXPECT_EQ(id, "w1");
    EXPECT_EQ(info["slots"], 3);
    EXPECT_EQ(info["cores"], 1);
    EXPECT_EQ(info["version"], api::kProtocolVersion);
    EXPECT_EQ(info["capabilities"]["spectral"], true);
    EXPECT_FALSE(info.contains("token"));
    return 0;
  });
  EXPECT_EQ(broker_->stats().workers, 1u);
}

TEST_F(BrokerTest, WrongVersionIsRefusedWithAFatalDisconnect) {
  start();
  auto p = peer();
  api::ReadyMsg r = RawPeer::ready("w1");
  r.version = api::kProtocolVersion + 1;
  p->send(r);
  auto bye = p->receive_a<api::DisconnectMsg>();
  ASSERT_TRUE(bye);
  EXPECT_TRUE(bye->fatal);
  EXPECT_NE(bye->reason.find("version"), std::string::npos);
  EXPECT_EQ(broker_->stats().rejected, 1u);
  EXPECT_EQ(broker_->stats().workers, 0u);
}

TEST_F(BrokerTest, UnknownPeerIsAskedToReregister) {
  start();
  auto p = peer();
  p->send(api::HeartbeatMsg{});
  EXPECT_TRUE(p->receive_a<api::ReregisterMsg>());
  api::ResultMsg result;
  result.unit = {"j", 0, 0, 0, 9};
  result.film_tile = "bytes";
  p->send(result);
  EXPECT_TRUE(p->receive_a<api::ReregisterMsg>());
  EXPECT_TRUE(backend_.with_lock([](auto& b) { return b.done.empty(); }));  // not from a stranger
}

TEST_F(BrokerTest, CreditLimitsUnitsToTheWorkersSlots) {
  start();
  for (int i = 0; i < 3; ++i) backend_.add_unit("j", i, 0, 0, "{}");
  auto p = joined_peer("w1", 1);
  auto u = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  EXPECT_EQ(u->unit.tile, 0);
  EXPECT_EQ(u->request, "{}");
  EXPECT_TRUE(no_unit_for(*p, 300ms)) << "a second unit beyond the worker's 1 slot";
  p->send(api::ResultMsg{u->unit, 10, 0.01, "tile"});
  auto u2 = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u2);
  EXPECT_EQ(u2->unit.tile, 1);
  EXPECT_NE(u2->unit.attempt, u->unit.attempt);
  ASSERT_TRUE(backend_.wait_for([](auto& b) { return b.done.size() == 1; }));
  backend_.with_lock([&](auto& b) {
    EXPECT_EQ(b.done[0].worker, "w1");
    EXPECT_EQ(b.done[0].attempt, u->unit.attempt);
    EXPECT_EQ(b.done[0].paths, 10u);
    EXPECT_EQ(std::string(b.done[0].bytes.begin(), b.done[0].bytes.end()), "tile");
    EXPECT_EQ(b.max_held["w1"], 1);
    return 0;
  });
}

// A worker announcing "prefetch" gets no more than its slots until its
// results say how long units take; short ones (1 ms against the 100 ms
// pipeline target) then earn it slots + prefetch, and never more.
TEST_F(BrokerTest, PrefetchGivesShortUnitsCreditUpToSlotsPlusPrefetch) {
  start();
  for (int i = 0; i < 40; ++i) backend_.add_unit("j", i, 0, 0, "{}");
  auto p = peer();
  api::ReadyMsg ready = RawPeer::ready("w1", 2);
  ready.prefetch = 6;
  p->send(ready);
  ASSERT_TRUE(p->receive_a<api::HeartbeatMsg>().has_value());
  std::vector<api::UnitMsg> held;
  for (int i = 0; i < 2; ++i) {
    auto u = p->receive_a<api::UnitMsg>();
    ASSERT_TRUE(u);
    held.push_back(*u);
  }
  EXPECT_TRUE(no_unit_for(*p, 200ms)) << "beyond the slots before any result";
  p->send(api::ResultMsg{held[0].unit, 1, 0.001, "tile"});
  held.erase(held.begin());
  // Now 8 units may be out: 7 more arrive, then nothing.
  for (int i = 0; i < 7; ++i) {
    auto u = p->receive_a<api::UnitMsg>();
    ASSERT_TRUE(u) << i;
    held.push_back(*u);
  }
  EXPECT_TRUE(no_unit_for(*p, 200ms)) << "beyond slots + prefetch";
  backend_.with_lock([&](auto& b) {
    EXPECT_EQ(b.max_held["w1"], 8);
    return 0;
  });
}

TEST_F(BrokerTest, SlotsAreFilledAndFailuresFreeThem) {
  start();
  for (int i = 0; i < 4; ++i) backend_.add_unit("j", i, 0, 0, "{}");
  auto p = joined_peer("w1", 3);
  std::vector<api::UnitMsg> units;
  for (int i = 0; i < 3; ++i) {
    auto u = p->receive_a<api::UnitMsg>();
    ASSERT_TRUE(u);
    units.push_back(*u);
  }
  EXPECT_TRUE(no_unit_for(*p, 200ms));
  p->send(api::FailedMsg{units[1].unit, "out of memory"});
  ASSERT_TRUE(p->receive_a<api::UnitMsg>());
  ASSERT_TRUE(backend_.wait_for([](auto& b) { return b.failed.size() == 1; }));
  backend_.with_lock([&](auto& b) {
    EXPECT_EQ(b.failed[0].attempt, units[1].unit.attempt);
    EXPECT_EQ(b.failed[0].message, "out of memory");
    EXPECT_EQ(b.failed[0].key, (UnitKey{"j", 1, 0, 0}));
    return 0;
  });
}

TEST_F(BrokerTest, SilentWorkerExpiresAndItsUnitsAreRequeued) {
  start();
  backend_.add_unit("j", 0, 0, 0, "{}");
  auto p = joined_peer("w1", 1);
  ASSERT_TRUE(p->receive_a<api::UnitMsg>());
  const auto t0 = std::chrono::steady_clock::now();
  // No more messages from the peer: 3 x 100 ms later it is lost.
  ASSERT_TRUE(backend_.wait_for([](auto& b) { return b.left.size() == 1; }, 3s));
  const auto waited = std::chrono::steady_clock::now() - t0;
  EXPECT_GE(waited, 200ms);
  EXPECT_LT(waited, 1500ms);
  EXPECT_EQ(broker_->stats().lost, 1u);
  EXPECT_EQ(backend_.with_lock([](auto& b) { return b.queue_.size(); }), 1u);
  // Once forgotten, its heartbeat is answered with REREGISTER.
  p->send(api::HeartbeatMsg{});
  EXPECT_TRUE(p->receive_a<api::ReregisterMsg>());
}

TEST_F(BrokerTest, HeartbeatingWorkerStaysAndIsHeartbeated) {
  start();
  auto p = joined_peer("w1", 1);
  int heartbeats = 0;
  const auto until = std::chrono::steady_clock::now() + 700ms;
  while (std::chrono::steady_clock::now() < until) {
    p->send(api::HeartbeatMsg{100, false});
    if (p->receive_a<api::HeartbeatMsg>(100ms)) ++heartbeats;
  }
  EXPECT_GE(heartbeats, 4);
  EXPECT_TRUE(backend_.with_lock([](auto& b) { return b.left.empty(); }));
}

TEST_F(BrokerTest, ResultsForAttemptsNotSentToTheWorkerAreRefused) {
  start();
  backend_.add_unit("j", 0, 0, 0, "{}");
  backend_.add_unit("j", 1, 0, 0, "{}");
  auto a = joined_peer("w1", 1);
  auto ua = a->receive_a<api::UnitMsg>();
  ASSERT_TRUE(ua);
  auto b = joined_peer("w2", 1);
  auto ub = b->receive_a<api::UnitMsg>();
  ASSERT_TRUE(ub);
  // w2 answers w1's attempt, an attempt nobody holds, and its own attempt with another tile.
  b->send(api::ResultMsg{ua->unit, 1, 0.1, "forged"});
  api::UnitRef unknown = ub->unit;
  unknown.attempt += 100;
  b->send(api::FailedMsg{unknown, "forged"});
  api::UnitRef other_tile = ub->unit;
  other_tile.tile = ua->unit.tile;
  b->send(api::ResultMsg{other_tile, 1, 0.1, "forged"});
  ASSERT_TRUE(eventually([&] { return broker_->stats().results_refused == 3; }));
  // Nothing reached the backend, and each attempt stays with its holder.
  a->send(api::ResultMsg{ua->unit, 1, 0.1, "a"});
  b->send(api::ResultMsg{ub->unit, 1, 0.1, "b"});
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 2; }));
  backend_.with_lock([&](auto& f) {
    EXPECT_TRUE(f.failed.empty());
    for (const auto& d : f.done) {
      EXPECT_EQ(d.worker, d.attempt == ua->unit.attempt ? "w1" : "w2");
      EXPECT_EQ(std::string(d.bytes.begin(), d.bytes.end()), d.worker == "w1" ? "a" : "b");
    }
    return 0;
  });
  EXPECT_EQ(broker_->stats().results_refused, 3u);
  EXPECT_EQ(broker_->stats().results, 2u);
}

TEST_F(BrokerTest, TheLateAnswerOfACancelledAttemptIsDroppedNotRefused) {
  start();
  backend_.add_unit("j", 0, 0, 0, "{}");
  auto p = joined_peer("w1", 1);
  auto u = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  backend_.cancel(u->unit.attempt);
  ASSERT_TRUE(p->receive_a<api::CancelMsg>());
  p->send(api::ResultMsg{u->unit, 1, 0.1, "late"});
  p->send(api::ResultMsg{u->unit, 1, 0.1, "again"});  // the second one is a refusal
  ASSERT_TRUE(eventually([&] { return broker_->stats().results_refused == 1; }));
  EXPECT_TRUE(backend_.with_lock([](auto& f) { return f.done.empty(); }));
}

TEST_F(BrokerTest, CancelReachesTheHolderAndFreesItsSlot) {
  start();
  backend_.add_unit("j", 0, 0, 0, "{}");
  backend_.add_unit("j", 1, 0, 0, "{}");
  auto p = joined_peer("w1", 1);
  auto u = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  backend_.cancel(u->unit.attempt);
  auto c = p->receive_a<api::CancelMsg>();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->attempt, u->unit.attempt);
  auto next = p->receive_a<api::UnitMsg>();  // the slot is free again
  ASSERT_TRUE(next);
  EXPECT_EQ(next->unit.tile, 1);
  EXPECT_EQ(broker_->stats().cancels_sent, 1u);
}

TEST_F(BrokerTest, DrainingWorkerGetsNoMoreUnits) {
  start();
  backend_.add_unit("j", 0, 0, 0, "{}");
  backend_.add_unit("j", 1, 0, 0, "{}");
  auto p = joined_peer("w1", 1);
  auto u = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  p->send(api::HeartbeatMsg{100, true});
  p->send(api::ResultMsg{u->unit, 1, 0.1, "tile"});
  EXPECT_TRUE(no_unit_for(*p, 300ms, api::HeartbeatMsg{100, true}));
  p->send(api::DisconnectMsg{"worker draining", false});
  ASSERT_TRUE(backend_.wait_for([](auto& b) { return b.left.size() == 1; }));
  backend_.with_lock([](auto& b) {
    EXPECT_EQ(b.done.size(), 1u);
    EXPECT_EQ(b.queue_.size(), 1u);
    return 0;
  });
}

TEST_F(BrokerTest, DisconnectAndReconnectWithTheSameIdReplaceTheRegistration) {
  start();
  auto a = joined_peer("w1", 1);
  a->send(api::DisconnectMsg{});
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 1; }));
  auto b = joined_peer("w1", 1);  // the same worker on a new socket
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.joined.size() == 2; }));
  EXPECT_EQ(broker_->stats().workers, 1u);
  b->send(api::DisconnectMsg{});
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 2; }));
  EXPECT_EQ(broker_->stats().workers, 0u);
}

TEST_F(BrokerTest, ALiveWorkersIdCannotBeTakenOver) {
  BrokerOptions o = test_options();
  o.heartbeat_liveness = 20;
  start(o);
  backend_.add_unit("j", 0, 0, 0, "{}");
  // The holder heartbeats every 500 ms: it has missed one after 1 s of silence
  // (and would expire after 10 s), so a loaded machine cannot make it look dead.
  auto a = peer();
  api::ReadyMsg holder = RawPeer::ready("w1", 1);
  holder.heartbeat_ms = 500;
  a->send(holder);
  ASSERT_TRUE(a->receive_a<api::HeartbeatMsg>());
  auto u = a->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  auto thief = peer();
  thief->send(RawPeer::ready("w1", 1));
  auto bye = thief->receive_a<api::DisconnectMsg>();
  ASSERT_TRUE(bye);
  EXPECT_TRUE(bye->fatal);
  EXPECT_NE(bye->reason.find("in use"), std::string::npos) << bye->reason;
  // The holder keeps its registration and its unit.
  a->send(api::ResultMsg{u->unit, 1, 0.1, "tile"});
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 1; }));
  backend_.with_lock([](auto& f) {
    EXPECT_TRUE(f.left.empty());
    EXPECT_EQ(f.joined.size(), 1u);
    EXPECT_EQ(f.done[0].worker, "w1");
    return 0;
  });
  EXPECT_EQ(broker_->stats().rejected, 1u);
  // Once the holder has missed heartbeats, the id may be claimed again (a reconnect).
  std::this_thread::sleep_for(1200ms);
  auto again = joined_peer("w1", 1);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.joined.size() == 2 && f.left.size() == 1; }));
}

// --- CURVE -------------------------------------------------------------------

constexpr const char* kSecret = "broker-test-worker-secret";

BrokerOptions curve_options() {
  BrokerOptions o = test_options();
  o.curve_secret_key = api::derive_server_keys(kSecret).secret_key;
  o.auth.allowed_keys = {api::derive_worker_keys(kSecret).public_key};
  return o;
}

class BrokerCurveTest : public BrokerTest {
 protected:
  std::unique_ptr<RawPeer> curve_peer(const api::CurveKeyPair& keys) {
    return std::make_unique<RawPeer>(ctx_, broker_->bound_endpoint(), keys, api::derive_server_keys(kSecret).public_key);
  }
  // True when `keys` get the welcome heartbeat for their READY.
  bool joins(const api::CurveKeyPair& keys, const std::string& id, std::chrono::milliseconds wait = 5000ms) {
    auto p = curve_peer(keys);
    p->send(RawPeer::ready(id));
    return p->receive_a<api::HeartbeatMsg>(wait).has_value();
  }
};

TEST_F(BrokerCurveTest, AWorkerWithTheDerivedSecretJoinsAndGetsUnits) {
  start(curve_options());
  backend_.add_unit("j", 0, 0, 0, "{}");
  auto p = curve_peer(api::derive_worker_keys(kSecret));
  p->send(RawPeer::ready("w1"));
  ASSERT_TRUE(p->receive_a<api::HeartbeatMsg>());
  auto u = p->receive_a<api::UnitMsg>();
  ASSERT_TRUE(u);
  p->send(api::ResultMsg{u->unit, 1, 0.1, "tile"});
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 1; }));
  EXPECT_EQ(broker_->stats().auth_failures, 0u);
}

TEST_F(BrokerCurveTest, ANullMechanismPeerGetsNothingAndIsCounted) {
  start(curve_options());
  backend_.add_unit("j", 0, 0, 0, "{}");
  auto p = peer();  // no CURVE
  p->send(RawPeer::ready("intruder"));
  EXPECT_FALSE(p->receive(500ms).has_value());
  ASSERT_TRUE(eventually([&] { return broker_->stats().auth_failures >= 1; }));
  EXPECT_TRUE(backend_.with_lock([](auto& f) { return f.joined.empty() && f.dispatches.empty(); }));
}

TEST_F(BrokerCurveTest, AnUnknownKeyIsDenied) {
  start(curve_options());
  EXPECT_FALSE(joins(api::generate_curve_keys(), "stranger", 500ms));
  EXPECT_GE(broker_->stats().auth_failures, 1u);
  // A key derived from another secret is just as unknown.
  EXPECT_FALSE(joins(api::derive_worker_keys("some-other-secret-text"), "guess", 500ms));
  EXPECT_TRUE(backend_.with_lock([](auto& f) { return f.joined.empty(); }));
}

TEST_F(BrokerCurveTest, TheAllowListAdmitsItsKeysAndIsRereadWhenItChanges) {
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_broker_keys_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto list = dir / "workers.keys";
  const api::CurveKeyPair first = api::generate_curve_keys(), second = api::generate_curve_keys();
  std::ofstream(list) << "# workers\n" << first.public_key << " first\n";
  BrokerOptions o = curve_options();
  o.auth.allowed_keys.clear();  // the allow-list alone
  o.auth.keys_path = list.string();
  o.auth.max_failures = 1000;   // the denied peer's retries must not lock out the loopback address
  start(o);
  EXPECT_TRUE(joins(first, "first"));
  EXPECT_FALSE(joins(second, "second", 500ms));
  EXPECT_GE(broker_->stats().auth_failures, 1u);
  std::ofstream(list, std::ios::app) << second.public_key << "\n";
  EXPECT_TRUE(joins(second, "second"));
  // A folder of *.pub files works the same way.
  broker_->stop();
  const auto folder = dir / "keys.d";
  std::filesystem::create_directories(folder);
  o.auth.keys_path = folder.string();
  start(o);
  EXPECT_FALSE(joins(first, "first-again", 500ms));
  std::ofstream(folder / "first.pub") << first.public_key << "\n";
  EXPECT_TRUE(joins(first, "first-again"));
  std::filesystem::remove_all(dir);
}

TEST_F(BrokerCurveTest, RepeatedFailuresLockTheAddressOutEvenForAValidKey) {
  BrokerOptions o = curve_options();
  o.auth.max_failures = 3;
  start(o);
  ASSERT_TRUE(eventually([&] {
    EXPECT_FALSE(joins(api::generate_curve_keys(), "stranger", 100ms));
    return broker_->stats().auth_failures >= 3;
  }));
  const auto before = broker_->stats().auth_failures;
  EXPECT_FALSE(joins(api::derive_worker_keys(kSecret), "w1", 500ms));
  EXPECT_TRUE(eventually([&] { return broker_->stats().auth_failures > before; }));
  EXPECT_TRUE(backend_.with_lock([](auto& f) { return f.joined.empty(); }));
}

// ASSET_GET: the file asset_file returns, or a refusal naming the id; a
// stranger is asked to register first and never gets a file.
TEST_F(BrokerTest, AssetGetIsAnsweredFromTheStore) {
  const std::string known = "sha256:" + std::string(64, 'a');
  const std::string unknown = "sha256:" + std::string(64, 'b');
  const std::string file("SKYMESH1\0payload", 16);
  std::atomic<int> reads{0};
  BrokerOptions o = test_options();
  o.asset_file = [&](const std::string& id) -> std::optional<std::string> {
    ++reads;
    if (id == known) return file;
    return std::nullopt;
  };
  start(o);
  auto stranger = peer();
  stranger->send(api::AssetGetMsg{known});
  EXPECT_TRUE(stranger->receive_a<api::ReregisterMsg>());
  EXPECT_EQ(reads.load(), 0) << "a peer that did not READY gets no asset";

  auto p = joined_peer("w1");
  p->send(api::AssetGetMsg{known});
  auto got = p->receive_a<api::AssetMsg>();
  ASSERT_TRUE(got);
  EXPECT_TRUE(got->ok);
  EXPECT_EQ(got->id, known);
  EXPECT_EQ(got->file, file);
  p->send(api::AssetGetMsg{unknown});
  auto refused = p->receive_a<api::AssetMsg>();
  ASSERT_TRUE(refused);
  EXPECT_FALSE(refused->ok);
  EXPECT_EQ(refused->id, unknown);
  EXPECT_NE(refused->error.find(unknown), std::string::npos) << refused->error;
  EXPECT_TRUE(refused->file.empty());
  EXPECT_EQ(broker_->stats().assets_served, 1u);
  EXPECT_EQ(broker_->stats().assets_refused, 1u);
  EXPECT_EQ(broker_->stats().workers, 1u) << "asking for assets is no reason to drop a worker";
}

TEST_F(BrokerTest, WithoutAStoreEveryAssetGetIsRefused) {
  start();
  auto p = joined_peer("w1");
  const std::string id = "sha256:" + std::string(64, 'c');
  p->send(api::AssetGetMsg{id});
  auto refused = p->receive_a<api::AssetMsg>();
  ASSERT_TRUE(refused);
  EXPECT_FALSE(refused->ok);
  EXPECT_NE(refused->error.find(id), std::string::npos) << refused->error;
}

TEST_F(BrokerTest, MalformedFramesAreCountedAndDropped) {
  start();
  auto raw = peer();
  const std::vector<api::Frames> garbage = {
      {""},
      {"READY"},
      {"READY", "{bad json"},
      {"READY", "[]"},
      {"READY", R"({"id": "x", "cores": -1, "slots": 1, "version": 1})"},
      {"RESULT", R"({"job": "j"})"},
      {"HELLO", "{}"},
      {std::string(1000, '\xff'), std::string(5000, '\0')},
      {"CANCEL", std::string(50000, '{')},
      {"UNIT", "{}", "a", "b", "c", "d"},
  };
  for (const auto& g : garbage) raw->send_frames(g);
  ASSERT_TRUE(eventually([&] { return broker_->stats().malformed >= garbage.size(); }, 2s))
      << broker_->stats().malformed;
  // Still serving: a proper READY on the same socket is accepted.
  raw->send(RawPeer::ready("after-garbage"));
  EXPECT_TRUE(raw->receive_a<api::HeartbeatMsg>());
  EXPECT_TRUE(backend_.wait_for([](auto& b) { return b.joined.size() == 1; }));
  // Valid messages a worker must not send are counted too.
  api::UnitMsg unit;
  unit.unit = {"j", 0, 0, 0, 1};
  unit.request = "{}";
  raw->send(unit);
  raw->send(api::CancelMsg{1});
  EXPECT_TRUE(eventually([&] { return broker_->stats().unexpected == 2; }, 2s));
}

TEST_F(BrokerTest, StopSendsDisconnectAndWorkerLeft) {
  start();
  auto p = joined_peer("w1", 1);
  broker_->stop();
  auto bye = p->receive_a<api::DisconnectMsg>();
  ASSERT_TRUE(bye);
  EXPECT_FALSE(bye->fatal);
  EXPECT_EQ(backend_.with_lock([](auto& b) { return b.left.size(); }), 1u);
}

// A backend whose every call throws: the broker logs, counts and carries on.
class ThrowingBackend : public FakeBackend {
 public:
  std::optional<UnitAssignment> next_unit(const std::string&) override { throw std::runtime_error("db down"); }
  void worker_joined(const std::string&, const nlohmann::json&) override { throw std::runtime_error("db down"); }
};

TEST(BrokerBackendErrors, ExceptionsFromTheBackendDoNotStopTheBroker) {
  ThrowingBackend backend;
  BrokerOptions o = test_options();
  Broker broker(backend, o);
  broker.start();
  zmq::context_t ctx;
  RawPeer p(ctx, broker.bound_endpoint());
  p.send(RawPeer::ready("w1"));
  EXPECT_TRUE(p.receive_a<api::HeartbeatMsg>());
  std::this_thread::sleep_for(100ms);
  EXPECT_GE(broker.stats().backend_errors, 2u);
  EXPECT_TRUE(broker.running());
  broker.stop();
}

}  // namespace
}  // namespace skyfarm::server

// The farm worker (worker/farm_worker.h) against the real broker and a fake
// backend over loopback: bit-identical results, credit, failures, CANCEL,
// hung workers, drain, reconnects, refusal, and the skyfarm-worker program
// draining on SIGTERM.  Heartbeats are 100 ms so every test takes well under
// two seconds.
#include "worker/farm_worker.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <thread>

#include "api/probe_spec.h"
#include "api/render_spec.h"
#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"
#include "common/assets/mesh_source.h"
#include "common/assets/triangle_mesh.h"
#include "common/render/parallel.h"
#include "common/render/tile_renderer.h"
#include "server/broker/broker.h"
#include "tests/server/broker/fake_broker_backend.h"

extern char** environ;

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using skyfarm::testing::eventually;
using skyfarm::testing::FakeBackend;
using skyfarm::testing::tiny_request;

// What `skyfarm-worker render` computes for one unit.
std::vector<std::uint8_t> local_unit_bytes(const std::string& request, int tile, int batch, int pass) {
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(request)));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  FilmTile film = renderer.empty_tile(tile);
  PathCounters counters;
  renderer.render_unit(WorkUnit{tile, batch, pass}, &film, &counters);
  return film.serialize();
}

server::BrokerOptions broker_options(int liveness = 5) {
  server::BrokerOptions o;
  o.endpoint = "tcp://127.0.0.1:*";
  o.heartbeat_interval = 100ms;
  o.heartbeat_liveness = liveness;
  o.log = [](std::string_view) {};
  return o;
}

FarmWorkerOptions worker_options(const std::string& endpoint) {
  FarmWorkerOptions o;
  o.endpoint = endpoint;
  o.threads = 1;
  o.heartbeat_interval = 100ms;
  o.heartbeat_liveness = 5;
  o.reconnect_initial = 100ms;
  o.reconnect_max = 400ms;
  o.drain_linger = 200ms;
  o.log = [](std::string_view) {};
  return o;
}

// A FarmWorker running on its own thread; drained and joined on destruction.
struct WorkerThread {
  explicit WorkerThread(FarmWorkerOptions o) : worker(std::move(o)), thread([this] { rc = worker.run(); }) {}
  ~WorkerThread() { finish(); }
  int finish() {
    worker.set_paused_for_testing(false);
    worker.request_drain();
    if (thread.joinable()) thread.join();
    return rc;
  }
  FarmWorker worker;
  std::atomic<int> rc{-1};
  std::thread thread;
};

class FarmWorkerTest : public ::testing::Test {
 protected:
  void start_broker(server::BrokerOptions o = broker_options()) {
    broker_ = std::make_unique<server::Broker>(backend_, o);
    broker_->start();
  }
  WorkerThread& start_worker(FarmWorkerOptions o) {
    workers_.push_back(std::make_unique<WorkerThread>(std::move(o)));
    return *workers_.back();
  }
  WorkerThread& start_worker() { return start_worker(worker_options(broker_->bound_endpoint())); }
  bool joined(std::size_t n) {
    return backend_.wait_for([&](auto& b) { return b.joined.size() >= n; });
  }
  void TearDown() override {
    workers_.clear();  // drain while the broker still answers
    if (broker_) broker_->stop();
  }

  FakeBackend backend_;
  std::unique_ptr<server::Broker> broker_;
  std::vector<std::unique_ptr<WorkerThread>> workers_;
};

TEST_F(FarmWorkerTest, ResultsAreBitIdenticalToALocalRender) {
  start_broker();
  const std::string a = tiny_request(48), b = tiny_request(16);
  backend_.add_units("a", 2, 2, 1, a);
  backend_.add_units("b", 1, 2, 1, b);
  FarmWorkerOptions o = worker_options(broker_->bound_endpoint());
  o.threads = 2;
  WorkerThread& w = start_worker(o);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 6; }, 10s));
  backend_.with_lock([&](auto& f) {
    EXPECT_TRUE(f.failed.empty());
    for (const auto& d : f.done) {
      const std::string& request = d.key.job_id == "a" ? a : b;
      EXPECT_EQ(d.bytes, local_unit_bytes(request, d.key.tile, d.key.batch, d.key.pass))
          << d.key.job_id << " tile " << d.key.tile << " batch " << d.key.batch;
      EXPECT_GT(d.paths, 0u);
      EXPECT_EQ(d.worker, w.worker.id());
    }
    const auto& info = f.joined.at(0).second;
    EXPECT_EQ(info["cores"], 2);
    EXPECT_EQ(info["slots"], 3);
    EXPECT_EQ(info["capabilities"]["spectral"], true);
    return 0;
  });
  EXPECT_EQ(w.finish(), 0);
}

TEST_F(FarmWorkerTest, DefaultSlotsAreThreadsPlusOne) {
  FarmWorkerOptions o;
  o.threads = 3;
  EXPECT_EQ(FarmWorker(o).slots(), 4);
  o.slots = 1;
  EXPECT_EQ(FarmWorker(o).slots(), 1);
  o.threads = 0;
  o.slots = 0;
  FarmWorker all(o);
  EXPECT_EQ(all.threads(), resolve_thread_count(0));
  EXPECT_FALSE(all.id().empty());
  EXPECT_NE(FarmWorker(o).id(), all.id());
}

TEST_F(FarmWorkerTest, AWorkerWithOneSlotNeverHoldsTwoUnits) {
  start_broker();
  backend_.add_units("a", 2, 2, 1, tiny_request(48));
  backend_.add_units("b", 1, 2, 1, tiny_request(16));
  FarmWorkerOptions o = worker_options(broker_->bound_endpoint());
  o.threads = 2;
  o.slots = 1;
  WorkerThread& w = start_worker(o);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 6; }, 10s));
  EXPECT_EQ(backend_.with_lock([&](auto& f) { return f.max_held[w.worker.id()]; }), 1);
}

TEST_F(FarmWorkerTest, FailuresCarryTheWorkersMessage) {
  start_broker();
  backend_.add_unit("bad", 0, 0, 0, R"({"camera": {"width": -3}})");
  backend_.add_unit("far", 7, 0, 0, tiny_request(16));  // the plan has 1 tile
  backend_.add_unit("ok", 0, 1, 0, tiny_request(16));
  start_worker();
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.failed.size() == 2 && f.done.size() == 1; }));
  backend_.with_lock([](auto& f) {
    EXPECT_EQ(f.failed[0].key.job_id, "bad");
    EXPECT_NE(f.failed[0].message.find("invalid request"), std::string::npos) << f.failed[0].message;
    EXPECT_NE(f.failed[0].message.find("camera.width"), std::string::npos) << f.failed[0].message;
    EXPECT_NE(f.failed[1].message.find("outside the job's plan"), std::string::npos) << f.failed[1].message;
    return 0;
  });
}

TEST_F(FarmWorkerTest, ACancelledUnitsResultIsNeverSent) {
  start_broker(broker_options(10));
  FarmWorkerOptions o = worker_options(broker_->bound_endpoint());
  o.heartbeat_liveness = 10;
  WorkerThread& w = start_worker(o);
  ASSERT_TRUE(joined(1));
  // The UNIT and its CANCEL both wait in the paused worker's socket.
  w.worker.set_paused_for_testing(true);
  backend_.add_unit("a", 0, 0, 0, tiny_request(16));
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.dispatches.size() == 1; }));
  const std::uint64_t cancelled = backend_.with_lock([](auto& f) { return f.dispatches[0].unit.attempt; });
  backend_.cancel(cancelled);
  ASSERT_TRUE(eventually([&] { return broker_->stats().cancels_sent == 1; }));
  w.worker.set_paused_for_testing(false);
  ASSERT_TRUE(eventually([&] { return w.worker.stats().cancels_received == 1; }));
  // Still serving; the cancelled attempt (rendered or not) never comes back.
  backend_.add_unit("a", 0, 1, 0, tiny_request(16));
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 1; }));
  backend_.with_lock([&](auto& f) {
    EXPECT_NE(f.done[0].attempt, cancelled);
    EXPECT_EQ(f.done[0].key.batch, 1);
    return 0;
  });
}

TEST_F(FarmWorkerTest, AHungWorkerIsDeclaredLostAndReregistersWhenItWakes) {
  start_broker(broker_options(3));
  WorkerThread& w = start_worker();
  ASSERT_TRUE(joined(1));
  w.worker.set_paused_for_testing(true);  // no heartbeats, no reads, like SIGSTOP
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 1; }, 3s));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1500ms);
  w.worker.set_paused_for_testing(false);
  ASSERT_TRUE(joined(2));
  backend_.with_lock([&](auto& f) {
    EXPECT_EQ(f.joined[1].first, w.worker.id());
    return 0;
  });
  backend_.add_unit("a", 0, 0, 0, tiny_request(16));
  EXPECT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 1; }));
}

TEST_F(FarmWorkerTest, DrainSendsPendingResultsThenDisconnects) {
  start_broker();
  backend_.set_dispatch_enabled(false);
  backend_.add_units("a", 2, 2, 1, tiny_request(48));
  FarmWorkerOptions o = worker_options(broker_->bound_endpoint());
  o.slots = 2;
  WorkerThread& w = start_worker(o);
  ASSERT_TRUE(joined(1));
  // Two units wait in the paused worker's socket when the drain begins.
  w.worker.set_paused_for_testing(true);
  backend_.set_dispatch_enabled(true);
  ASSERT_TRUE(eventually([&] { return broker_->stats().units_sent == 2; }));
  std::this_thread::sleep_for(100ms);  // loopback delivery into the worker's socket
  w.worker.request_drain();
  w.worker.set_paused_for_testing(false);
  w.thread.join();
  EXPECT_EQ(w.rc, 0);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 1; }));
  backend_.with_lock([](auto& f) {
    EXPECT_EQ(f.done.size(), 2u);
    EXPECT_EQ(f.dispatches.size(), 2u);  // draining: no more units
    EXPECT_EQ(f.queue_.size(), 2u);
    EXPECT_EQ(f.events.back().rfind("left:", 0), 0u);  // results first, then DISCONNECT
    return 0;
  });
  EXPECT_EQ(broker_->stats().lost, 0u);  // a DISCONNECT, not an expiry
}

TEST_F(FarmWorkerTest, ReconnectsAfterTheBrokerRestarts) {
  start_broker();
  const std::string endpoint = broker_->bound_endpoint();
  WorkerThread& w = start_worker();
  ASSERT_TRUE(joined(1));
  broker_->stop();
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 1; }));
  server::BrokerOptions o = broker_options();
  o.endpoint = endpoint;
  start_broker(o);
  ASSERT_TRUE(joined(2));
  EXPECT_GE(w.worker.stats().sessions, 2u);
  backend_.add_unit("a", 0, 0, 0, tiny_request(16));
  EXPECT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 1; }));
}

TEST_F(FarmWorkerTest, ReconnectsOnANewSocketWhenTheServerGoesSilent) {
  zmq::context_t ctx;
  zmq::socket_t router(ctx, zmq::socket_type::router);
  router.set(zmq::sockopt::linger, 0);
  router.bind("tcp://127.0.0.1:*");
  FarmWorkerOptions o = worker_options(router.get(zmq::sockopt::last_endpoint));
  o.heartbeat_liveness = 3;
  WorkerThread& w = start_worker(o);
  std::vector<std::string> ready_from;  // identities that sent READY
  const auto until = std::chrono::steady_clock::now() + 4s;
  while (ready_from.size() < 2 && std::chrono::steady_clock::now() < until) {
    zmq::pollitem_t item{router.handle(), 0, ZMQ_POLLIN, 0};
    if (zmq::poll(&item, 1, 100ms) <= 0) continue;
    std::vector<zmq::message_t> parts;
    ASSERT_TRUE(zmq::recv_multipart(router, std::back_inserter(parts)));
    ASSERT_GE(parts.size(), 2u);
    if (parts[1].to_string() == "READY") ready_from.push_back(parts[0].to_string());
  }
  ASSERT_EQ(ready_from.size(), 2u);
  EXPECT_NE(ready_from[0], ready_from[1]);  // a fresh socket, as the Paranoid Pirate does
  EXPECT_EQ(w.finish(), 0);
}

constexpr const char* kSecret = "farm-worker-test-secret";

server::BrokerOptions curve_broker_options() {
  server::BrokerOptions o = broker_options();
  o.curve_secret_key = api::derive_server_keys(kSecret).secret_key;
  o.auth.allowed_keys = {api::derive_worker_keys(kSecret).public_key};
  return o;
}

FarmWorkerOptions curve_worker_options(const std::string& endpoint, const api::CurveKeyPair& own) {
  FarmWorkerOptions o = worker_options(endpoint);
  o.server_key = api::derive_server_keys(kSecret).public_key;
  o.public_key = own.public_key;
  o.secret_key = own.secret_key;
  return o;
}

TEST_F(FarmWorkerTest, AWorkerWithTheDerivedSecretRendersOverCurve) {
  start_broker(curve_broker_options());
  const std::string request = tiny_request(16);
  backend_.add_units("a", 1, 2, 1, request);
  start_worker(curve_worker_options(broker_->bound_endpoint(), api::derive_worker_keys(kSecret)));
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 2; }, 10s));
  backend_.with_lock([&](auto& f) {
    for (const auto& d : f.done) EXPECT_EQ(d.bytes, local_unit_bytes(request, d.key.tile, d.key.batch, d.key.pass));
    return 0;
  });
  EXPECT_EQ(broker_->stats().auth_failures, 0u);
}

TEST_F(FarmWorkerTest, AWorkerWithAnUnknownKeyNeverJoinsAndSaysWhy) {
  start_broker(curve_broker_options());
  backend_.add_units("a", 1, 2, 1, tiny_request(16));
  std::vector<std::string> lines;
  std::mutex mu;
  FarmWorkerOptions o = curve_worker_options(broker_->bound_endpoint(), api::generate_curve_keys());
  o.log = [&](std::string_view line) {
    std::lock_guard lock(mu);
    lines.emplace_back(line);
  };
  WorkerThread& w = start_worker(o);
  ASSERT_TRUE(eventually([&] { return w.worker.stats().auth_failures >= 1; }, 3s));
  EXPECT_GE(broker_->stats().auth_failures, 1u);
  EXPECT_TRUE(backend_.with_lock([](auto& f) { return f.joined.empty() && f.dispatches.empty(); }));
  EXPECT_EQ(w.finish(), 0);  // before `lines` goes: the worker logs into it
  std::lock_guard lock(mu);
  EXPECT_TRUE(std::any_of(lines.begin(), lines.end(),
                          [](const std::string& l) { return l.find("refused the CURVE handshake") != std::string::npos; }));
}

TEST_F(FarmWorkerTest, AnIdInUseEndsRunWithOne) {
  // A 1 s broker interval: the holder (heartbeating every 100 ms) looks dead
  // only after 2 s of silence, which no loaded machine reaches here.
  server::BrokerOptions bo = broker_options();
  bo.heartbeat_interval = 1000ms;
  start_broker(bo);
  FarmWorkerOptions first = worker_options(broker_->bound_endpoint());
  first.id = "twin";
  start_worker(first);
  ASSERT_TRUE(joined(1));
  WorkerThread& second = start_worker(first);
  ASSERT_TRUE(eventually([&] { return second.rc.load() != -1; }, 3s));
  EXPECT_EQ(second.rc, 1);
  EXPECT_EQ(broker_->stats().rejected, 1u);
  EXPECT_EQ(broker_->stats().workers, 1u);
}

// --- The program -------------------------------------------------------------

pid_t spawn_worker(const std::vector<std::string>& args, const std::vector<std::string>& env_extra) {
  std::vector<std::string> all = {SKYFARM_WORKER_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = env_extra;
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind("SKYFARM_", 0) != 0) env_strings.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = -1;
  if (::posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), envp.data()) != 0) return -1;
  return pid;
}

// Exit status of `pid`, or -1 if it has not exited within `timeout`.
int wait_exit(pid_t pid, std::chrono::milliseconds timeout) {
  int status = 0;
  const bool exited = eventually([&] { return ::waitpid(pid, &status, WNOHANG) == pid; }, timeout);
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST_F(FarmWorkerTest, ProgramDrainsOnSigtermAndExitsZero) {
  start_broker(curve_broker_options());
  backend_.add_units("a", 2, 2, 1, tiny_request(48));
  // The secret reaches the program through the environment, as the server hands it to its local workers.
  const pid_t pid = spawn_worker({"--threads", "1"}, {"SKYFARM_CONNECT=" + broker_->bound_endpoint(), "SKYFARM_SLOTS=1",
                                                      std::string("SKYFARM_WORKER_SECRET=") + kSecret});
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(joined(1));
  EXPECT_EQ(backend_.with_lock([](FakeBackend& f) { return f.joined[0].second["slots"].get<int>(); }), 1);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 4; }, 10s));
  ::kill(pid, SIGTERM);
  EXPECT_EQ(wait_exit(pid, 5s), 0);
  EXPECT_TRUE(backend_.wait_for([](auto& f) { return f.left.size() == 1; }));
  EXPECT_EQ(broker_->stats().lost, 0u);
}

TEST_F(FarmWorkerTest, ProgramRejectsBadFlags) {
  EXPECT_EQ(wait_exit(spawn_worker({"--threads", "many"}, {}), 5s), 2);
  EXPECT_EQ(wait_exit(spawn_worker({"--connect", "nowhere"}, {}), 5s), 2);
  EXPECT_EQ(wait_exit(spawn_worker({"--frobnicate", "1"}, {}), 5s), 2);
  EXPECT_EQ(wait_exit(spawn_worker({}, {"SKYFARM_SLOTS=-2"}), 5s), 2);
  // No credential for a server beyond loopback; a key file without the server's key; a short secret.
  EXPECT_EQ(wait_exit(spawn_worker({"--connect", "tcp://192.0.2.1:5555"}, {}), 5s), 2);
  EXPECT_EQ(wait_exit(spawn_worker({"--connect", "tcp://192.0.2.1:5555"}, {"SKYFARM_WORKER_SECRET=short"}), 5s), 2);
  const auto key = std::filesystem::temp_directory_path() / ("skyfarm_worker_key_" + std::to_string(::getpid()));
  std::filesystem::remove(key);
  std::filesystem::remove(key.string() + ".pub");
  EXPECT_EQ(wait_exit(spawn_worker({"keygen", key.string()}, {}), 5s), 0);
  EXPECT_EQ(std::filesystem::status(key).permissions() & std::filesystem::perms::all, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_EQ(wait_exit(spawn_worker({"keygen", key.string()}, {}), 5s), 2);  // never overwrites a key
  EXPECT_EQ(wait_exit(spawn_worker({"--connect", "tcp://192.0.2.1:5555", "--key-file", key.string()}, {}), 5s), 2);
  std::filesystem::remove(key);
  std::filesystem::remove(key.string() + ".pub");
}

}  // namespace
}  // namespace skyfarm

namespace skyfarm {
namespace {

// Probe units (UNIT kind "probe"): the worker advertises them, traces them
// on its render threads exactly as the local probe does (the RESULT's sums
// are the bytes of trace_probe_unit), and answers a unit outside the plan,
// or a probe that is not path traced, with FAILED.
TEST_F(FarmWorkerTest, ProbeUnitsAreTracedAsTheLocalProbeDoes) {
  start_broker();
  const api::ProbeRequest probe = api::parse_probe_request(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 0},
      "directions": [{"zenith_deg": 30, "azimuth_deg": 0}], "wavelengths_nm": [500, 600], "samples": 300})");
  const std::string text = api::canonical_text(probe);
  api::ProbeRequest lut = probe;
  lut.method = api::Method::kLut;
  backend_.with_lock([&](auto& f) {
    using server::UnitAssignment, server::UnitKey;
    f.queue_.push_back(UnitAssignment{UnitKey{"probe-1", 0, 0, 0}, 0, text, api::UnitKind::kProbe});
    f.queue_.push_back(UnitAssignment{UnitKey{"probe-1", 5, 0, 0}, 0, text, api::UnitKind::kProbe});
    f.queue_.push_back(UnitAssignment{UnitKey{"probe-2", 0, 0, 0}, 0, api::canonical_text(lut), api::UnitKind::kProbe});
    return 0;
  });
  start_worker();
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() + f.failed.size() == 3; }, 10s));
  const ProbeSpec spec = api::probe_spec(probe);
  const ProbePlan plan = probe_plan(spec);
  const Scene scene = probe_scene(spec);
  ASSERT_TRUE(probe_roulette_control(spec, scene)) << "sun 40 deg from the zenith";
  const std::vector<std::uint8_t> expected =
      trace_probe_unit(scene, spec.directions, probe.wavelengths_nm, probe.seed, plan.unit(0),
                       probe_roulette_control(spec, scene))
          .serialize();
  backend_.with_lock([&](auto& f) {
    EXPECT_EQ(f.joined.at(0).second["capabilities"]["probe"], api::kProbeUnitsVersion);
    ASSERT_EQ(f.done.size(), 1u);
    EXPECT_EQ(f.done[0].bytes, expected);
    EXPECT_EQ(f.done[0].paths, 600u);
    ASSERT_EQ(f.failed.size(), 2u);
    for (const auto& failed : f.failed) {
      if (failed.key.job_id == "probe-1")
        EXPECT_NE(failed.message.find("outside the probe's 1 units"), std::string::npos) << failed.message;
      else
        EXPECT_NE(failed.message.find("method is lut"), std::string::npos) << failed.message;
    }
  });
}

// --- Mesh assets -----------------------------------------------------------------------

// A tetrahedron in front of an equirectangular camera, and its mesh file.
const std::string& tetra_file() {
  static const std::string file = [] {
    assets::TriangleMesh m;
    m.positions = {-1, 2, 0, 1, 2, 0, 0, 3, 0, 0, 2.5, 1.5};
    m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return assets::encode_mesh_file(assets::canonicalize_mesh(m));
  }();
  return file;
}

std::string mesh_request(const std::string& asset) {
  const std::string body = R"({"sun": {"zenith_deg": 60, "azimuth_deg": 120},
      "camera": {"projection": "equirectangular", "width": 64, "height": 8},
      "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 2},
      "objects": [{"shape": "mesh", "asset": ")" + asset + R"(", "albedo": 0.5}]})";
  return api::canonical_text(api::parse_render_request(body));
}

// Serves the tetrahedron, as the farm worker's cache would once fetched.
struct OneMesh : assets::MeshSource {
  std::shared_ptr<const assets::TriangleMesh> mesh(std::string_view) const override {
    auto m = std::make_shared<assets::TriangleMesh>();
    std::string error;
    EXPECT_TRUE(assets::decode_mesh_file(tetra_file(), {}, m.get(), &error)) << error;
    return m;
  }
};

std::vector<std::uint8_t> local_mesh_unit_bytes(const std::string& request, int tile, int batch, int pass) {
  const OneMesh meshes;
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(request)), &meshes);
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  FilmTile film = renderer.empty_tile(tile);
  PathCounters counters;
  renderer.render_unit(WorkUnit{tile, batch, pass}, &film, &counters);
  return film.serialize();
}

// Two render threads and two jobs naming the same asset: one ASSET_GET, the
// bytes of a local render, the file kept in the disk cache for the next worker.
TEST_F(FarmWorkerTest, AMeshAssetIsFetchedOnceAndRendersAsLocally) {
  const std::string id = assets::asset_id_of(tetra_file());
  std::atomic<int> reads{0};
  // Generous liveness on both sides: on a loaded machine a 0.5 s silence
  // made the broker drop the busy worker and refuse its reconnection (its id
  // still in use), which is not what this test is about.
  server::BrokerOptions o = broker_options(50);
  o.asset_file = [&](const std::string& asked) -> std::optional<std::string> {
    ++reads;
    if (asked == id) return tetra_file();
    return std::nullopt;
  };
  start_broker(o);
  const std::string request = mesh_request(id);
  backend_.add_units("m1", 2, 2, 1, request);
  backend_.add_units("m2", 2, 2, 1, request);
  const fs::path cache = fs::temp_directory_path() / ("skyfarm_fw_assets_" + std::to_string(::getpid()));
  fs::remove_all(cache);
  FarmWorkerOptions wo = worker_options(broker_->bound_endpoint());
  wo.heartbeat_liveness = 50;
  wo.threads = 2;
  wo.asset_cache_dir = cache.string();
  WorkerThread& w = start_worker(wo);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() + f.failed.size() == 8; }, 20s));
  backend_.with_lock([&](auto& f) {
    for (const auto& failed : f.failed) ADD_FAILURE() << failed.key.job_id << ": " << failed.message;
    for (const auto& d : f.done)
      EXPECT_EQ(d.bytes, local_mesh_unit_bytes(request, d.key.tile, d.key.batch, d.key.pass))
          << d.key.job_id << " tile " << d.key.tile << " batch " << d.key.batch;
    return 0;
  });
  EXPECT_EQ(reads.load(), 1);
  EXPECT_EQ(w.worker.stats().assets_requested, 1u);
  EXPECT_EQ(w.worker.stats().assets_received, 1u);
  EXPECT_TRUE(fs::exists(cache / (std::string(assets::asset_hex(id)) + ".mesh")));
  EXPECT_EQ(w.finish(), 0);

  // A second worker with the same cache never asks.
  backend_.add_units("m3", 1, 1, 1, request);
  WorkerThread& again = start_worker(wo);
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.done.size() == 9; }, 20s));
  EXPECT_EQ(again.worker.stats().assets_requested, 0u);
  EXPECT_EQ(reads.load(), 1);
  fs::remove_all(cache);
}

TEST_F(FarmWorkerTest, AnAssetTheServerLacksFailsTheUnitNamingIt) {
  start_broker();  // no asset store
  const std::string id = "sha256:" + std::string(64, '4');
  backend_.add_units("m", 1, 1, 1, mesh_request(id));
  start_worker();
  ASSERT_TRUE(backend_.wait_for([](auto& f) { return f.failed.size() == 1; }, 10s));
  backend_.with_lock([&](auto& f) {
    EXPECT_NE(f.failed[0].message.find(id), std::string::npos) << f.failed[0].message;
    return 0;
  });
}

}  // namespace
}  // namespace skyfarm

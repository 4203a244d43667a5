// The farm's worker security end to end on loopback: a broker beyond
// loopback needs a credential, local workers get the secret outside their
// command line, forged results are refused without changing a byte of the
// image, intruders are counted in /metrics, and allow-list workers join with
// their own key pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include "api/curve_keys.h"
#include "tests/farm/farm_process.h"
#include "tests/server/broker/fake_broker_backend.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::FarmServer;
using testing::RawPeer;

constexpr const char* kRequest = R"({
  "sun": {"zenith_deg": 50, "azimuth_deg": 100},
  "camera": {"projection": "equirectangular", "width": 64, "height": 32},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 16},
  "output": {"half": false},
  "seed": 5
})";

fs::path fresh_dir(const std::string& name) { return testing::fresh_dir("skyfarm_sec", name); }

// The local render of kRequest (computed once).
const std::string& reference_exr() {
  static const std::string bytes = testing::local_render_exr(kRequest, fresh_dir("reference"));
  return bytes;
}

// Exit status of `pid`, or -1 if it has not exited within `timeout`.
int wait_exit(pid_t pid, std::chrono::milliseconds timeout) {
  int status = 0;
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (::waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > until) {
      testing::kill_and_wait(pid);
      return -1;
    }
    std::this_thread::sleep_for(20ms);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The value of an unlabelled Prometheus sample, or -1.
double metric(const FarmServer& server, const std::string& name) {
  auto c = server.client();
  const auto res = c.Get("/metrics");
  if (!res || res->status != 200) return -1;
  const std::regex line("(^|\n)" + name + " ([0-9.e+]+)");
  std::smatch m;
  return std::regex_search(res->body, m, line) ? std::stod(m[2]) : -1;
}

// Process ids whose parent is `parent`.
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = testing::read_text(e.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 2));
    char state = 0;
    pid_t ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent) out.push_back(std::stoi(name));
  }
  return out;
}

TEST(FarmSecurity, ABrokerBeyondLoopbackWithoutCredentialExitsTwo) {
  const fs::path dir = fresh_dir("open");
  const pid_t pid = testing::spawn_process({SKYFARM_SERVER_BINARY, "--listen", "127.0.0.1:0", "--broker", "tcp://0.0.0.0:0",
                                            "--local-workers", "0", "--data-dir", (dir / "data").string()},
                                           dir / "server.log");
  EXPECT_EQ(wait_exit(pid, 10s), 2);
  const std::string log = testing::read_text(dir / "server.log");
  EXPECT_NE(log.find("--worker-secret-file"), std::string::npos) << log;
  EXPECT_NE(log.find("--worker-keys"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "data" / "keys" / "worker.secret"));
}

TEST(FarmSecurity, LocalWorkersGetTheSecretOutsideTheirCommandLine) {
  const fs::path dir = fresh_dir("local");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string secret = api::read_secret_file(server.secret_file().string());
  EXPECT_EQ(fs::status(server.secret_file()).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  std::vector<pid_t> workers;
  for (int i = 0; i < 100 && workers.size() < 2; ++i) {
    workers = children_of(server.pid());
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_EQ(workers.size(), 2u);
  for (const pid_t w : workers) {
    std::string cmdline = testing::read_text("/proc/" + std::to_string(w) + "/cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    EXPECT_NE(cmdline.find("skyfarm-worker"), std::string::npos) << cmdline;
    EXPECT_EQ(cmdline.find(secret), std::string::npos) << cmdline;
    EXPECT_EQ(cmdline.find("--token"), std::string::npos) << cmdline;
    const std::string environ = testing::read_text("/proc/" + std::to_string(w) + "/environ");
    EXPECT_NE(environ.find("SKYFARM_WORKER_SECRET=" + secret), std::string::npos);
  }
  // They joined: the job is done.
  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  ASSERT_EQ(server.wait(id, 60s)["state"], "done");
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
}

TEST(FarmSecurity, ForgedResultsAreRefusedAndTheImageIsUnchanged) {
  const fs::path dir = fresh_dir("forged");
  FarmServer server(dir / "data", 1);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string secret = api::read_secret_file(server.secret_file().string());
  zmq::context_t ctx;
  // An intruder without CURVE gets nothing and is counted.
  RawPeer intruder(ctx, server.endpoint());
  intruder.send(RawPeer::ready("intruder"));
  EXPECT_FALSE(intruder.receive(300ms).has_value());
  // A worker holding the secret that answers attempts it was never sent.
  RawPeer rogue(ctx, server.endpoint(), api::derive_worker_keys(secret), api::derive_server_keys(secret).public_key);
  rogue.send(RawPeer::ready("rogue", 1));
  ASSERT_TRUE(rogue.receive_a<api::HeartbeatMsg>(5s));
  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  const auto unit = rogue.receive_a<api::UnitMsg>(10s);
  ASSERT_TRUE(unit);
  int forged = 0;
  for (std::uint64_t a = unit->unit.attempt > 10 ? unit->unit.attempt - 10 : 1; a < unit->unit.attempt + 30; ++a) {
    if (a == unit->unit.attempt) continue;
    api::UnitRef ref = unit->unit;
    ref.attempt = a;
    rogue.send(api::ResultMsg{ref, 1, 0.1, std::string(64, 'x')});
    ++forged;
  }
  api::UnitRef other_tile = unit->unit;
  other_tile.tile += 1;
  rogue.send(api::ResultMsg{other_tile, 1, 0.1, std::string(64, 'x')});
  ++forged;
  rogue.send(api::DisconnectMsg{"done forging", false});  // its own unit goes back to the queue
  const auto status = server.wait(id, 60s);
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
  EXPECT_GE(metric(server, "skyfarm_results_refused_total"), forged);
  EXPECT_GE(metric(server, "skyfarm_worker_auth_failures_total"), 1);
}

TEST(FarmSecurity, AnAllowListedWorkerJoinsWithItsOwnKeyPair) {
  const fs::path dir = fresh_dir("allow");
  const fs::path key = dir / "worker.key", list = dir / "workers.keys";
  ASSERT_EQ(wait_exit(testing::spawn_process({SKYFARM_WORKER_BINARY, "keygen", key.string()}, dir / "keygen.log"), 10s), 0);
  std::ofstream(list) << "# the farm's workers\n";
  FarmServer server(dir / "data", 0, "tcp://127.0.0.1:*", {"--worker-keys", list.string()});
  ASSERT_TRUE(server.ok()) << server.log();
  const fs::path server_pub = dir / "data" / "keys" / "server.key.pub";
  ASSERT_TRUE(fs::exists(server_pub));
  EXPECT_FALSE(fs::exists(server.secret_file()));  // an allow-list: no shared secret is written
  const std::vector<std::string> worker = {SKYFARM_WORKER_BINARY, "--connect", server.endpoint(), "--threads", "1",
                                           "--key-file", key.string(), "--server-key", server_pub.string()};
  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  // Not listed yet: nothing happens; listed: the job runs.
  const pid_t early = testing::spawn_process(worker, dir / "early.log");
  for (int i = 0; i < 100 && metric(server, "skyfarm_worker_auth_failures_total") < 1; ++i)
    std::this_thread::sleep_for(50ms);
  EXPECT_GE(metric(server, "skyfarm_worker_auth_failures_total"), 1);
  EXPECT_EQ(server.status(id)["progress"]["units_done"], 0);
  testing::kill_and_wait(early);
  std::ofstream(list, std::ios::app) << testing::read_text(key.string() + ".pub");
  const pid_t joined = testing::spawn_process(worker, dir / "joined.log");
  const auto status = server.wait(id, 60s);
  testing::kill_and_wait(joined, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump() << testing::read_text(dir / "joined.log");
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
}

}  // namespace
}  // namespace skyfarm

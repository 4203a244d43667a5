// The worker admission policy (server/broker/worker_auth.h): fixed keys, the
// allow-list file or folder re-read on change, and the per-address lock-out
// with its cool-down (time is passed in, so no test waits for it).
#include "server/broker/worker_auth.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "api/curve_keys.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

fs::path fresh_dir() {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_worker_auth_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(WorkerAuth, AllowListLinesThatAreNotKeysAreReportedAndSkipped) {
  const fs::path dir = fresh_dir();
  const std::string key = api::generate_curve_keys().public_key;
  std::ofstream(dir / "list") << "# workers\n\n" << key << "  render-01\nnot-a-key\n";
  std::vector<std::string> errors;
  const auto keys = read_worker_keys((dir / "list").string(), &errors);
  EXPECT_EQ(keys, std::set<std::string>{key});
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find(":4:"), std::string::npos) << errors[0];
  errors.clear();
  EXPECT_TRUE(read_worker_keys((dir / "missing").string(), &errors).empty());
  EXPECT_EQ(errors.size(), 1u);
  fs::remove_all(dir);
}

TEST(WorkerAuth, RepeatedFailuresLockAnAddressOutUntilTheCoolDownEnds) {
  WorkerAuthOptions o;
  const std::string good = api::generate_curve_keys().public_key, bad = api::generate_curve_keys().public_key;
  o.allowed_keys = {good};
  o.max_failures = 3;
  o.failure_window = 60s;
  o.cooldown = 60s;
  WorkerAuth auth(o, [](const std::string&) {});
  const auto t0 = WorkerAuth::Clock::now();
  EXPECT_TRUE(auth.check("10.0.0.1", good, t0).allowed);
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(auth.check("10.0.0.1", bad, t0 + 1s).allowed);
  EXPECT_FALSE(auth.check("10.0.0.1", good, t0 + 2s).allowed);  // locked out, valid key or not
  EXPECT_TRUE(auth.check("10.0.0.2", good, t0 + 2s).allowed);   // other addresses are not
  EXPECT_TRUE(auth.check("10.0.0.1", good, t0 + 62s).allowed);  // the cool-down is over
  // Failures spread wider than the window never add up to a lock-out.
  for (int i = 0; i < 6; ++i) EXPECT_FALSE(auth.check("10.0.0.3", bad, t0 + i * 40s).allowed);
  EXPECT_TRUE(auth.check("10.0.0.3", good, t0 + 241s).allowed);
}

}  // namespace
}  // namespace skyfarm::server

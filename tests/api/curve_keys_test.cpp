// CURVE credentials shared by the server and the workers (api/curve_keys.h):
// derivation, key files, secrets and what counts as loopback.
#include "api/curve_keys.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <zmq.h>

namespace skyfarm::api {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir() {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_curve_keys_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string public_of(const std::string& secret_key) {
  char pub[41] = {};
  EXPECT_EQ(zmq_curve_public(pub, secret_key.c_str()), 0);
  return pub;
}

TEST(CurveKeys, BothEndsDeriveTheSamePairsAndTheRolesDiffer) {
  const CurveKeyPair worker = derive_worker_keys("a shared secret of some length");
  const CurveKeyPair server = derive_server_keys("a shared secret of some length");
  EXPECT_EQ(worker, derive_worker_keys("a shared secret of some length"));
  EXPECT_NE(worker.public_key, server.public_key);
  EXPECT_NE(worker.public_key, derive_worker_keys("another shared secret text").public_key);
  EXPECT_TRUE(is_z85_key(worker.public_key));
  EXPECT_EQ(public_of(worker.secret_key), worker.public_key);  // a valid Curve25519 pair
  EXPECT_EQ(public_of(server.secret_key), server.public_key);
}

TEST(CurveKeys, KeyFilesRoundTripAndAreNeverOverwritten) {
  const fs::path dir = fresh_dir();
  const CurveKeyPair keys = generate_curve_keys();
  write_key_pair((dir / "k").string(), keys);
  EXPECT_EQ(fs::status(dir / "k").permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(read_key_file((dir / "k").string()), keys);
  EXPECT_EQ(read_public_key((dir / "k.pub").string()), keys.public_key);
  EXPECT_EQ(read_public_key(keys.public_key), keys.public_key);
  EXPECT_THROW(write_key_pair((dir / "k").string(), generate_curve_keys()), std::runtime_error);
  EXPECT_EQ(read_key_file((dir / "k").string()), keys);
  EXPECT_THROW(read_public_key("not-a-key"), std::runtime_error);
  std::ofstream(dir / "bad") << "# comment\nshort\n";
  EXPECT_THROW(read_key_file((dir / "bad").string()), std::runtime_error);
  fs::remove_all(dir);
}

TEST(CurveKeys, SecretsAreCheckedAndKeptOnce) {
  const fs::path dir = fresh_dir();
  EXPECT_THROW(checked_secret("short", "SKYFARM_WORKER_SECRET"), std::runtime_error);
  EXPECT_EQ(checked_secret("  sixteen-chars-or-more\n", "x"), "sixteen-chars-or-more");
  const std::string path = (dir / "keys" / "worker.secret").string();
  const std::string first = ensure_secret_file(path);
  EXPECT_EQ(first.size(), 64u);
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(ensure_secret_file(path), first);  // reused across restarts
  EXPECT_EQ(read_secret_file(path), first);
  EXPECT_THROW(read_secret_file((dir / "missing").string()), std::runtime_error);
  fs::remove_all(dir);
}

TEST(CurveKeys, LoopbackEndpoints) {
  for (const char* e : {"tcp://127.0.0.1:5555", "tcp://127.1.2.3:*", "tcp://localhost:5555", "tcp://[::1]:5555",
                        "ipc:///tmp/skyfarm.sock", "inproc://broker"})
    EXPECT_TRUE(is_loopback_endpoint(e)) << e;
  for (const char* e : {"tcp://0.0.0.0:5555", "tcp://*:5555", "tcp://10.0.0.1:5555", "tcp://[::]:5555",
                        "tcp://eth0:5555", "tcp://farm.example:5555", "udp://127.0.0.1:5555"})
    EXPECT_FALSE(is_loopback_endpoint(e)) << e;
}

}  // namespace
}  // namespace skyfarm::api

// skyfarm-server's flags (a contract) and their environment variables.
#include "server/server_options.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace skyfarm::server {
namespace {

TEST(ServerOptions, DefaultsMatchTheDesign) {
  ServerOptions o;
  ASSERT_EQ(parse_server_options({}, &o), "");
  EXPECT_EQ(o.listen, "127.0.0.1:8080");
  EXPECT_EQ(o.broker, "tcp://127.0.0.1:5555");
  EXPECT_EQ(o.local_workers, -1);  // one per core
  EXPECT_EQ(o.data_dir, "./skyfarm-data");
  EXPECT_TRUE(o.token.empty());
}

TEST(ServerOptions, FlagsBeatEnvironmentWhichBeatsDefaults) {
  ::setenv("SKYFARM_LOCAL_WORKERS", "3", 1);
  ::setenv("SKYFARM_DATA_DIR", "/tmp/from-env", 1);
  ServerOptions o;
  ASSERT_EQ(parse_server_options({"--local-workers", "0", "--token", "s3cret", "--listen", "0.0.0.0:9000"}, &o), "");
  ::unsetenv("SKYFARM_LOCAL_WORKERS");
  ::unsetenv("SKYFARM_DATA_DIR");
  EXPECT_EQ(o.local_workers, 0);
  EXPECT_EQ(o.data_dir, "/tmp/from-env");
  EXPECT_EQ(o.token, "s3cret");
  EXPECT_EQ(o.listen, "0.0.0.0:9000");
}

TEST(ServerOptions, BadValuesNameTheFlag) {
  ServerOptions o;
  EXPECT_EQ(parse_server_options({"--local-workers", "-1"}, &o), "--local-workers: invalid value '-1'");
  EXPECT_EQ(parse_server_options({"--listen", "nohost"}, &o), "--listen: expected HOST:PORT, got 'nohost'");
  EXPECT_EQ(parse_server_options({"--frobnicate"}, &o), "unknown option '--frobnicate'");
  EXPECT_EQ(parse_server_options({"--data-dir"}, &o), "--data-dir: a value is required");
  ::setenv("SKYFARM_UNIT_TIMEOUT", "soon", 1);
  EXPECT_EQ(parse_server_options({}, &o), "--unit-timeout: invalid value 'soon' (from SKYFARM_UNIT_TIMEOUT)");
  ::unsetenv("SKYFARM_UNIT_TIMEOUT");
}

TEST(ServerOptions, WorkerCredentialFlagsAndTheirVariables) {
  ::setenv("SKYFARM_WORKER_KEYS", "/etc/skyfarm/workers.keys", 1);
  ::setenv("SKYFARM_WORKER_SECRET_FILE", "/env/worker.secret", 1);
  ServerOptions o;
  ASSERT_EQ(parse_server_options({"--worker-secret-file", "/flag/worker.secret", "--server-key-file", "/k/server.key"}, &o),
            "");
  ::unsetenv("SKYFARM_WORKER_KEYS");
  ::unsetenv("SKYFARM_WORKER_SECRET_FILE");
  EXPECT_EQ(o.worker_secret_file, "/flag/worker.secret");
  EXPECT_EQ(o.worker_keys, "/etc/skyfarm/workers.keys");
  EXPECT_EQ(o.server_key_file, "/k/server.key");
  EXPECT_TRUE(o.token.empty());  // the HTTP token is not a worker credential
}

// The cache sizes and the probe timeout: defaults, flags, environment, and
// bad values refused naming the flag and the range.
TEST(ServerOptions, CacheSizesAndProbeTimeout) {
  ServerOptions o;
  ASSERT_EQ(parse_server_options({}, &o), "");
  EXPECT_EQ(o.sky_cache_mb, 256);
  EXPECT_EQ(o.envmap_cache_mb, 128);
  EXPECT_EQ(o.probe_timeout_s, 120.0);
  ::setenv("SKYFARM_ENVMAP_CACHE_MB", "64", 1);
  ::setenv("SKYFARM_SKY_CACHE_MB", "999", 1);
  ASSERT_EQ(parse_server_options({"--sky-cache-mb", "512", "--probe-timeout", "2.5"}, &o), "");
  ::unsetenv("SKYFARM_ENVMAP_CACHE_MB");
  ::unsetenv("SKYFARM_SKY_CACHE_MB");
  EXPECT_EQ(o.sky_cache_mb, 512);
  EXPECT_EQ(o.envmap_cache_mb, 64);
  EXPECT_EQ(o.probe_timeout_s, 2.5);
  ASSERT_EQ(parse_server_options({"--envmap-cache-mb", "0"}, &o), "");
  EXPECT_EQ(o.envmap_cache_mb, 0) << "0 keeps nothing";

  ServerOptions bad;
  EXPECT_EQ(parse_server_options({"--sky-cache-mb", "-1"}, &bad),
            "--sky-cache-mb: invalid value '-1' (a whole number of MiB in [0, 1048576])");
  EXPECT_EQ(parse_server_options({"--sky-cache-mb", "1.5"}, &bad),
            "--sky-cache-mb: invalid value '1.5' (a whole number of MiB in [0, 1048576])");
  EXPECT_EQ(parse_server_options({"--envmap-cache-mb", "lots"}, &bad),
            "--envmap-cache-mb: invalid value 'lots' (a whole number of MiB in [0, 1048576])");
  EXPECT_EQ(parse_server_options({"--envmap-cache-mb", "1048577"}, &bad),
            "--envmap-cache-mb: invalid value '1048577' (a whole number of MiB in [0, 1048576])");
  EXPECT_EQ(parse_server_options({"--probe-timeout", "0"}, &bad),
            "--probe-timeout: invalid value '0' (seconds in (0, 3600])");
  EXPECT_EQ(parse_server_options({"--probe-timeout", "1e9"}, &bad),
            "--probe-timeout: invalid value '1e9' (seconds in (0, 3600])");
  EXPECT_EQ(parse_server_options({"--sky-cache-mb"}, &bad), "--sky-cache-mb: a value is required");
  ::setenv("SKYFARM_SKY_CACHE_MB", "big", 1);
  EXPECT_EQ(parse_server_options({}, &bad),
            "--sky-cache-mb: invalid value 'big' (a whole number of MiB in [0, 1048576]) (from SKYFARM_SKY_CACHE_MB)");
  ::unsetenv("SKYFARM_SKY_CACHE_MB");
  EXPECT_EQ(bad.sky_cache_mb, 256) << "a refused value changes nothing";
}

// The HTTP deadlines and the connection cap: defaults, flags, environment,
// and bad values refused naming the flag and the range.
TEST(ServerOptions, HttpDeadlinesAndConnectionCap) {
  ServerOptions o;
  ASSERT_EQ(parse_server_options({}, &o), "");
  EXPECT_EQ(o.header_timeout_s, 10.0);
  EXPECT_EQ(o.body_timeout_s, 30.0);
  EXPECT_EQ(o.max_connections, 1024);
  ::setenv("SKYFARM_BODY_TIMEOUT", "45", 1);
  ::setenv("SKYFARM_MAX_CONNECTIONS", "99", 1);
  ASSERT_EQ(parse_server_options({"--header-timeout", "2.5", "--max-connections", "200"}, &o), "");
  ::unsetenv("SKYFARM_BODY_TIMEOUT");
  ::unsetenv("SKYFARM_MAX_CONNECTIONS");
  EXPECT_EQ(o.header_timeout_s, 2.5);
  EXPECT_EQ(o.body_timeout_s, 45.0);
  EXPECT_EQ(o.max_connections, 200);
  ServerOptions bad;
  EXPECT_EQ(parse_server_options({"--header-timeout", "0"}, &bad),
            "--header-timeout: invalid value '0' (seconds in (0, 3600])");
  EXPECT_EQ(parse_server_options({"--body-timeout", "1h"}, &bad),
            "--body-timeout: invalid value '1h' (seconds in (0, 3600])");
  EXPECT_EQ(parse_server_options({"--max-connections", "0"}, &bad),
            "--max-connections: invalid value '0' (a whole number in [1, 1000000])");
  ::setenv("SKYFARM_HEADER_TIMEOUT", "-1", 1);
  EXPECT_EQ(parse_server_options({}, &bad),
            "--header-timeout: invalid value '-1' (seconds in (0, 3600]) (from SKYFARM_HEADER_TIMEOUT)");
  ::unsetenv("SKYFARM_HEADER_TIMEOUT");
  EXPECT_EQ(bad.header_timeout_s, 10.0) << "a refused value changes nothing";
  EXPECT_EQ(bad.max_connections, 1024);
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// The disk budget and the retention: defaults (sized at start; a week),
// flags, environment, and bad values refused naming the flag and the range.
TEST(ServerOptions, DiskBudgetAndRetention) {
  ServerOptions o;
  ASSERT_EQ(parse_server_options({}, &o), "");
  EXPECT_EQ(o.max_disk_mb, -1) << "sized to the machine at start";
  EXPECT_EQ(o.retention_hours, 168.0);
  ::setenv("SKYFARM_MAX_DISK_MB", "2048", 1);
  ::setenv("SKYFARM_RETENTION_HOURS", "24", 1);
  ASSERT_EQ(parse_server_options({"--retention-hours", "0.5"}, &o), "");
  ::unsetenv("SKYFARM_MAX_DISK_MB");
  ::unsetenv("SKYFARM_RETENTION_HOURS");
  EXPECT_EQ(o.max_disk_mb, 2048);
  EXPECT_EQ(o.retention_hours, 0.5);
  ASSERT_EQ(parse_server_options({"--max-disk-mb", "0", "--retention-hours", "0"}, &o), "");
  EXPECT_EQ(o.max_disk_mb, 0) << "no limit";
  EXPECT_EQ(parse_server_options({"--max-disk-mb", "-5"}, &o),
            "--max-disk-mb: invalid value '-5' (a whole number of MiB in [0, 1073741824]; 0 = no limit)");
  EXPECT_EQ(parse_server_options({"--retention-hours", "forever"}, &o),
            "--retention-hours: invalid value 'forever' (hours in [0, 1000000]; 0 = never)");
}

}  // namespace
}  // namespace skyfarm::server

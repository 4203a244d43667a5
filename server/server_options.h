// skyfarm-server's command line (the names are a contract):
//   --listen 127.0.0.1:8080     HTTP address           (SKYFARM_LISTEN)
//   --broker tcp://127.0.0.1:5555  ZeroMQ ROUTER endpoint (SKYFARM_BROKER)
//   --local-workers N           local worker processes, default: cores; 0 = none (SKYFARM_LOCAL_WORKERS)
//   --data-dir ./skyfarm-data   jobs, tiles and images   (SKYFARM_DATA_DIR)
//   --token SECRET              bearer token for /v1 (SKYFARM_TOKEN); not a worker credential
//   --worker-secret-file PATH   shared worker secret; both ends derive CURVE keys from it, it never
//                               goes on the wire (SKYFARM_WORKER_SECRET_FILE)
//   --worker-keys PATH          allow-list of worker public keys (Z85): a file, one per line (# comments),
//                               or a folder of *.pub; re-read when it changes (SKYFARM_WORKER_KEYS)
//   --server-key-file PATH      the server's CURVE key pair from `skyfarm-server keygen PATH`; default:
//                               derived from the worker secret, or <data-dir>/keys/server.key made once
//                               (SKYFARM_SERVER_KEY_FILE)
//                               A --broker beyond loopback needs --worker-secret-file or --worker-keys
//                               (else exit 2); on loopback without either the server makes a secret
//                               once, in <data-dir>/keys/worker.secret (0600), for hand-started workers.
//   --worker-binary PATH        skyfarm-worker to start  (SKYFARM_WORKER_BINARY)
//   --unit-timeout S            requeue a unit after S seconds without a result (SKYFARM_UNIT_TIMEOUT)
//   --max-active-jobs N         queued + running jobs before 429 (SKYFARM_MAX_ACTIVE_JOBS)
//   --max-queue-units N         units waiting over all jobs before 429 (SKYFARM_MAX_QUEUE_UNITS)
//   --max-body-bytes N          request body limit, 413 beyond (SKYFARM_MAX_BODY_BYTES)
//   --probe-timeout S           a path-traced probe not answered after S seconds: 504, its units
//                               cancelled; (0, 3600], default 120 (SKYFARM_PROBE_TIMEOUT)
//   --sky-cache-mb N            MiB of LUT sky tables kept for /v1/sky and env maps; [0, 1048576],
//                               default 256; 0 keeps none (SKYFARM_SKY_CACHE_MB)
//   --envmap-cache-mb N         MiB of encoded env maps kept; [0, 1048576], default 128
//                               (SKYFARM_ENVMAP_CACHE_MB)
//   --ffmpeg PATH               ffmpeg for timelapse videos; default: ffmpeg on PATH (SKYFARM_FFMPEG)
//   --max-timelapse-frames N    frames per timelapse, 400 beyond; default 1000 (SKYFARM_MAX_TIMELAPSE_FRAMES)
//   --max-disk-mb N             MiB the data directory may hold: a render that would not fit beside
//                               the others gets 507; default: 80 % of the free space of its filesystem
//                               plus what it holds, at start; 0 = no limit (SKYFARM_MAX_DISK_MB)
//   --retention-hours H         finished renders' files are deleted H hours after they finish (the
//                               record stays, "expired": true); default 168; 0 = never
//                               (SKYFARM_RETENTION_HOURS)
//   --header-timeout S          a request head must arrive within S seconds (from the first byte, or
//                               the previous response's end); 408 and closed beyond; (0, 3600],
//                               default 10 (SKYFARM_HEADER_TIMEOUT)
//   --body-timeout S            a request body must arrive within S seconds after its head; (0, 3600],
//                               default 30 (SKYFARM_BODY_TIMEOUT)
//   --max-connections N         HTTP connections open at once, 503 and closed beyond; [1, 1000000],
//                               default 1024 (SKYFARM_MAX_CONNECTIONS)
// A flag beats its environment variable, which beats the default.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace skyfarm::server {

struct ServerOptions {
  std::string listen = "127.0.0.1:8080";
  std::string broker = "tcp://127.0.0.1:5555";
  int local_workers = -1;  // -1: one per core
  std::string data_dir = "./skyfarm-data";
  std::string token;
  std::string worker_secret_file;
  std::string worker_keys;
  std::string server_key_file;
  std::string worker_binary;
  double unit_timeout_s = 120.0;
  int max_active_jobs = 64;
  int max_queue_units = 4000000;
  long long max_body_bytes = 1 << 20;
  double probe_timeout_s = 120.0;
  long long sky_cache_mb = 256;
  long long envmap_cache_mb = 128;
  std::string ffmpeg;              // "": ffmpeg on PATH
  int max_timelapse_frames = 1000;
  long long max_disk_mb = -1;      // -1: sized to the machine at start
  double retention_hours = 168.0;  // 0: never
  double header_timeout_s = 10.0;
  double body_timeout_s = 30.0;
  int max_connections = 1024;
  bool help = false;
};

// Parses argv (without the program name) and the environment; returns an
// error message naming the flag, or "".
std::string parse_server_options(const std::vector<std::string>& args, ServerOptions* out);
extern const char* const kServerUsage;

}  // namespace skyfarm::server

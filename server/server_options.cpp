#include "server/server_options.h"

#include <cstdlib>
#include <stdexcept>

namespace skyfarm::server {

const char* const kServerUsage =
    "usage: skyfarm-server [--listen 127.0.0.1:8080] [--broker tcp://127.0.0.1:5555]\n"
    "                      [--local-workers N (default: cores; 0 = none)] [--data-dir ./skyfarm-data]\n"
    "                      [--token SECRET] [--worker-binary PATH] [--unit-timeout SECONDS]\n"
    "                      [--worker-secret-file PATH] [--worker-keys FILE|DIR] [--server-key-file PATH]\n"
    "                      [--max-active-jobs N] [--max-queue-units N] [--max-body-bytes N]\n"
    "                      [--probe-timeout SECONDS (default 120)] [--sky-cache-mb N (default 256)]\n"
    "                      [--envmap-cache-mb N (default 128)] [--ffmpeg PATH] [--max-timelapse-frames N]\n"
    "                      [--max-disk-mb N (default: 80 % of the free disk; 0 = no limit)]\n"
    "                      [--retention-hours H (default 168; 0 = never)]\n"
    "                      [--header-timeout SECONDS (default 10)] [--body-timeout SECONDS (default 30)]\n"
    "                      [--max-connections N (default 1024)]\n"
    "Every flag also reads SKYFARM_<NAME> from the environment (SKYFARM_LISTEN, SKYFARM_BROKER,\n"
    "SKYFARM_LOCAL_WORKERS, SKYFARM_DATA_DIR, SKYFARM_TOKEN, SKYFARM_WORKER_BINARY, SKYFARM_UNIT_TIMEOUT,\n"
    "SKYFARM_WORKER_SECRET_FILE, SKYFARM_WORKER_KEYS, SKYFARM_SERVER_KEY_FILE,\n"
    "SKYFARM_MAX_ACTIVE_JOBS, SKYFARM_MAX_QUEUE_UNITS, SKYFARM_MAX_BODY_BYTES, SKYFARM_PROBE_TIMEOUT,\n"
    "SKYFARM_SKY_CACHE_MB, SKYFARM_ENVMAP_CACHE_MB, SKYFARM_FFMPEG, SKYFARM_MAX_TIMELAPSE_FRAMES,\n"
    "SKYFARM_MAX_DISK_MB, SKYFARM_RETENTION_HOURS,\n"
    "SKYFARM_HEADER_TIMEOUT, SKYFARM_BODY_TIMEOUT, SKYFARM_MAX_CONNECTIONS).\n"
    "--probe-timeout: seconds a POST /v1/sky/radiance path probe may take on the farm (then 504).\n"
    "--sky-cache-mb, --envmap-cache-mb: MiB of LUT sky tables and of encoded env maps kept in memory\n"
    "for GET /v1/sky and /v1/sky/envmap.exr (least recently used evicted first; 0 keeps none).\n"
    "--max-disk-mb: MiB the data directory may hold; a render whose tiles and images would not fit\n"
    "beside the others is refused with 507 (default: 80 % of the free space plus what it holds, at start).\n"
    "--retention-hours: finished renders' files are deleted this long after they finish (images then 410).\n"
    "--header-timeout, --body-timeout: a client must send its whole request head (body) within this\n"
    "many seconds, else 408 and the connection is closed; slow clients hold no server thread meanwhile.\n"
    "--max-connections: HTTP connections open at once; one beyond is answered 503 and closed.\n"
    "Without a token the server listens on loopback only; give --token to listen beyond it.\n"
    "Workers authenticate with CURVE (the --token is for HTTP only): --worker-secret-file PATH (a shared\n"
    "secret, never sent; workers give --secret-file) and/or --worker-keys FILE|DIR (an allow-list of\n"
    "worker public keys from `skyfarm-worker keygen`, re-read when it changes); --server-key-file PATH\n"
    "(from `skyfarm-server keygen PATH`) is the server's own key pair.  A --broker beyond loopback needs\n"
    "one of the first two; on loopback without them the server keeps its own secret in\n"
    "<data-dir>/keys/worker.secret (mode 0600) for `skyfarm-worker --secret-file`.\n"
    "skyfarm-server keygen PATH writes a key pair: PATH (secret, 0600) and PATH.pub (public, Z85).\n";

namespace {

struct Flag {
  const char* name;
  const char* env;
};
constexpr Flag kFlags[] = {{"--listen", "SKYFARM_LISTEN"},
                           {"--broker", "SKYFARM_BROKER"},
                           {"--local-workers", "SKYFARM_LOCAL_WORKERS"},
                           {"--data-dir", "SKYFARM_DATA_DIR"},
                           {"--token", "SKYFARM_TOKEN"},
                           {"--worker-secret-file", "SKYFARM_WORKER_SECRET_FILE"},
                           {"--worker-keys", "SKYFARM_WORKER_KEYS"},
                           {"--server-key-file", "SKYFARM_SERVER_KEY_FILE"},
                           {"--worker-binary", "SKYFARM_WORKER_BINARY"},
                           {"--unit-timeout", "SKYFARM_UNIT_TIMEOUT"},
                           {"--max-active-jobs", "SKYFARM_MAX_ACTIVE_JOBS"},
                           {"--max-queue-units", "SKYFARM_MAX_QUEUE_UNITS"},
                           {"--max-body-bytes", "SKYFARM_MAX_BODY_BYTES"},
                           {"--probe-timeout", "SKYFARM_PROBE_TIMEOUT"},
                           {"--sky-cache-mb", "SKYFARM_SKY_CACHE_MB"},
                           {"--envmap-cache-mb", "SKYFARM_ENVMAP_CACHE_MB"},
                           {"--ffmpeg", "SKYFARM_FFMPEG"},
                           {"--max-timelapse-frames", "SKYFARM_MAX_TIMELAPSE_FRAMES"},
                           {"--max-disk-mb", "SKYFARM_MAX_DISK_MB"},
                           {"--retention-hours", "SKYFARM_RETENTION_HOURS"},
                           {"--header-timeout", "SKYFARM_HEADER_TIMEOUT"},
                           {"--body-timeout", "SKYFARM_BODY_TIMEOUT"},
                           {"--max-connections", "SKYFARM_MAX_CONNECTIONS"}};

constexpr long long kMaxCacheMb = 1 << 20;  // 1 TiB: a typo guard, not a memory check
constexpr double kMaxProbeTimeoutS = 3600.0;
constexpr long long kMaxDiskMb = 1LL << 30;  // 1 EiB: a typo guard
constexpr double kMaxRetentionHours = 1e6;
constexpr double kMaxRequestTimeoutS = 3600.0;  // --header-timeout, --body-timeout
constexpr long long kMaxConnections = 1000000;

// A whole decimal number in [lo, hi]; throws std::invalid_argument otherwise.
long long whole_number(const std::string& value, long long lo, long long hi) {
  std::size_t used = 0;
  const long long n = std::stoll(value, &used);
  if (used != value.size() || n < lo || n > hi) throw std::invalid_argument("range");
  return n;
}

// The flags whose error says the expected range.
std::string set_sizes_and_timeouts(const std::string& flag, const std::string& value, ServerOptions* o) {
  try {
    if (flag == "--sky-cache-mb" || flag == "--envmap-cache-mb") {
      (flag == "--sky-cache-mb" ? o->sky_cache_mb : o->envmap_cache_mb) = whole_number(value, 0, kMaxCacheMb);
    } else if (flag == "--max-disk-mb") {
      o->max_disk_mb = whole_number(value, 0, kMaxDiskMb);
    } else if (flag == "--retention-hours") {
      std::size_t used = 0;
      const double h = std::stod(value, &used);
      if (used != value.size() || !(h >= 0.0 && h <= kMaxRetentionHours)) throw std::invalid_argument("range");
      o->retention_hours = h;
    } else if (flag == "--probe-timeout" || flag == "--header-timeout" || flag == "--body-timeout") {
      std::size_t used = 0;
      const double s = std::stod(value, &used);
      const double max = flag == "--probe-timeout" ? kMaxProbeTimeoutS : kMaxRequestTimeoutS;
      if (used != value.size() || !(s > 0.0 && s <= max)) throw std::invalid_argument("range");
      (flag == "--probe-timeout" ? o->probe_timeout_s : flag == "--header-timeout" ? o->header_timeout_s : o->body_timeout_s) = s;
    } else if (flag == "--max-connections") {
      o->max_connections = static_cast<int>(whole_number(value, 1, kMaxConnections));
    }
  } catch (const std::exception&) {
    if (flag == "--max-connections") return flag + ": invalid value '" + value + "' (a whole number in [1, 1000000])";
    if (flag.ends_with("-timeout")) return flag + ": invalid value '" + value + "' (seconds in (0, 3600])";
    if (flag == "--max-disk-mb")
      return flag + ": invalid value '" + value + "' (a whole number of MiB in [0, 1073741824]; 0 = no limit)";
    if (flag == "--retention-hours")
      return flag + ": invalid value '" + value + "' (hours in [0, 1000000]; 0 = never)";
    return flag + ": invalid value '" + value + "' (a whole number of MiB in [0, 1048576])";
  }
  return "";
}

std::string set(const std::string& flag, const std::string& value, ServerOptions* o) {
  try {
    if (flag == "--listen") {
      if (value.rfind(':') == std::string::npos) return "--listen: expected HOST:PORT, got '" + value + "'";
      o->listen = value;
    } else if (flag == "--broker") {
      o->broker = value;
    } else if (flag == "--local-workers") {
      o->local_workers = static_cast<int>(whole_number(value, 0, 1024));
    } else if (flag == "--max-active-jobs") {
      o->max_active_jobs = static_cast<int>(whole_number(value, 1, 1000000));
    } else if (flag == "--max-queue-units") {
      o->max_queue_units = static_cast<int>(whole_number(value, 1, 1000000000));
    } else if (flag == "--max-body-bytes") {
      o->max_body_bytes = whole_number(value, 1024, 1LL << 30);
    } else if (flag == "--max-timelapse-frames") {
      o->max_timelapse_frames = static_cast<int>(whole_number(value, 2, 100000));
    } else if (flag == "--ffmpeg") {
      o->ffmpeg = value;
    } else if (flag == "--data-dir") {
      o->data_dir = value;
    } else if (flag == "--token") {
      o->token = value;
    } else if (flag == "--worker-secret-file") {
      o->worker_secret_file = value;
    } else if (flag == "--worker-keys") {
      o->worker_keys = value;
    } else if (flag == "--server-key-file") {
      o->server_key_file = value;
    } else if (flag == "--worker-binary") {
      o->worker_binary = value;
    } else if (flag == "--unit-timeout") {
      std::size_t used = 0;
      const double s = std::stod(value, &used);
      if (used != value.size() || !(s > 0.0)) throw std::invalid_argument("range");
      o->unit_timeout_s = s;
    }
  } catch (const std::exception&) {
    return flag + ": invalid value '" + value + "'";
  }
  return set_sizes_and_timeouts(flag, value, o);
}

}  // namespace

std::string parse_server_options(const std::vector<std::string>& args, ServerOptions* out) {
  for (const Flag& f : kFlags)
    if (const char* v = std::getenv(f.env); v && *v)
      if (std::string e = set(f.name, v, out); !e.empty()) return e + " (from " + f.env + ")";
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      out->help = true;
      continue;
    }
    bool known = false;
    for (const Flag& f : kFlags) known = known || a == f.name;
    if (!known) return "unknown option '" + a + "'";
    if (i + 1 >= args.size()) return a + ": a value is required";
    if (std::string e = set(a, args[++i], out); !e.empty()) return e;
  }
  return "";
}

}  // namespace skyfarm::server

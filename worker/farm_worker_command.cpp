// skyfarm-worker's default mode: the farm worker (farm_worker.h).
#include <cstdlib>
#include <iostream>
#include <optional>

#include <unistd.h>

#include "api/curve_keys.h"
#include "worker/asset_cache.h"
#include "worker/farm_worker.h"
#include "worker/signals.h"

namespace skyfarm {

const char* const kFarmWorkerUsage =
    "  [--connect URL] [--threads N] [--slots N] [--id NAME]\n"
    "  [--secret-file PATH] [--key-file PATH] [--server-key KEY|PATH] [--token SECRET]\n"
    "  [--asset-cache DIR] [--asset-cache-mb N]\n"
    "                                (default) a farm worker: connect to the server's broker\n"
    "                                (URL tcp://127.0.0.1:5555), render the units it hands out\n"
    "                                on N threads (0 = all cores) holding N+1 units (--slots);\n"
    "                                SIGTERM/SIGINT drain: finish the units, then leave.\n"
    "                                Traffic is CURVE-encrypted; the worker authenticates with\n"
    "                                --secret-file (the server's --worker-secret-file; or the\n"
    "                                secret itself in SKYFARM_WORKER_SECRET) or --key-file (its\n"
    "                                own pair from `skyfarm-worker keygen PATH`, listed in the\n"
    "                                server's --worker-keys) with --server-key (the server's\n"
    "                                public key, text or .pub file; derived from the secret when\n"
    "                                one is given).  With none on a loopback URL it uses\n"
    "                                ./skyfarm-data/keys/worker.secret if readable.  --token is\n"
    "                                still accepted and sent, but is no longer a credential.\n"
    "                                Mesh assets the units name are fetched from the server once\n"
    "                                and kept in --asset-cache DIR (default $CACHE_DIRECTORY/assets,\n"
    "                                else ~/.cache/skyfarm/assets, else /tmp/skyfarm-worker-UID/assets),\n"
    "                                at most --asset-cache-mb N (2048) MB, least recently used first out.\n"
    "                                Each flag also reads SKYFARM_CONNECT, SKYFARM_THREADS,\n"
    "                                SKYFARM_SLOTS, SKYFARM_ID, SKYFARM_WORKER_SECRET_FILE,\n"
    "                                SKYFARM_KEY_FILE, SKYFARM_SERVER_KEY, SKYFARM_TOKEN,\n"
    "                                SKYFARM_ASSET_CACHE, SKYFARM_ASSET_CACHE_MB\n";

namespace {

constexpr const char* kDefaultSecretFile = "./skyfarm-data/keys/worker.secret";

// The credential flags, resolved into FarmWorkerOptions by credentials().
struct Credentials {
  std::string secret_file, key_file, server_key;
};

std::optional<std::string> env(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return std::nullopt;
  return std::string(v);
}

// Reads a non-negative integer; an error text or "".
std::string read_count(const std::string& flag, const std::string& text, int* out) {
  std::size_t used = 0;
  long value = -1;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || value < 0 || value > 4096) return flag + ": expected an integer in [0, 4096], got '" + text + "'";
  *out = static_cast<int>(value);
  return "";
}

std::string apply(const std::string& flag, const std::string& value, FarmWorkerOptions* o, Credentials* c) {
  if (flag == "--secret-file" || flag == "--key-file" || flag == "--server-key") {
    if (value.empty()) return flag + ": a value is required";
    (flag == "--secret-file" ? c->secret_file : flag == "--key-file" ? c->key_file : c->server_key) = value;
    return "";
  }
  if (flag == "--connect") {
    if (value.find("://") == std::string::npos) return "--connect: expected an endpoint like tcp://HOST:PORT, got '" + value + "'";
    o->endpoint = value;
    return "";
  }
  if (flag == "--threads") return read_count(flag, value, &o->threads);
  if (flag == "--asset-cache") {
    if (value.empty()) return flag + ": a directory is required";
    o->asset_cache_dir = value;
    return "";
  }
  if (flag == "--asset-cache-mb") {
    std::size_t used = 0;
    long long mb = -1;
    try {
      mb = std::stoll(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != value.size() || mb < 1 || mb > (1ll << 30))
      return flag + ": expected a number of megabytes >= 1, got '" + value + "'";
    o->asset_cache_bytes = static_cast<std::size_t>(mb) << 20;
    return "";
  }
  if (flag == "--slots") return read_count(flag, value, &o->slots);
  if (flag == "--token") {
    o->token = value;
    return "";
  }
  if (flag == "--id") {
    o->id = value;
    return "";
  }
  return "unknown option '" + flag + "'";
}

std::string parse(const std::vector<std::string>& args, FarmWorkerOptions* o, Credentials* c) {
  const std::pair<const char*, const char*> from_env[] = {{"--connect", "SKYFARM_CONNECT"},
                                                          {"--threads", "SKYFARM_THREADS"},
                                                          {"--slots", "SKYFARM_SLOTS"},
                                                          {"--token", "SKYFARM_TOKEN"},
                                                          {"--id", "SKYFARM_ID"},
                                                          {"--secret-file", "SKYFARM_WORKER_SECRET_FILE"},
                                                          {"--key-file", "SKYFARM_KEY_FILE"},
                                                          {"--server-key", "SKYFARM_SERVER_KEY"},
                                                          {"--asset-cache", "SKYFARM_ASSET_CACHE"},
                                                          {"--asset-cache-mb", "SKYFARM_ASSET_CACHE_MB"}};
  for (const auto& [flag, name] : from_env)
    if (const auto v = env(name))
      if (std::string err = apply(flag, *v, o, c); !err.empty()) return std::string(name) + " (" + err + ")";
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string flag = args[i], value;
    if (const auto eq = flag.find('='); eq != std::string::npos && flag.rfind("--", 0) == 0) {
      value = flag.substr(eq + 1);
      flag.resize(eq);
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      return "option '" + flag + "' needs a value";
    }
    if (std::string err = apply(flag, value, o, c); !err.empty()) return err;
  }
  return "";
}

// Fills the CURVE keys of `o`; an error text naming the flag, or "".
std::string credentials(const Credentials& c, FarmWorkerOptions* o) {
  std::string secret, origin;
  try {
    if (const auto v = env("SKYFARM_WORKER_SECRET")) {
      origin = "SKYFARM_WORKER_SECRET";
      secret = api::checked_secret(*v, origin);
    } else if (!c.secret_file.empty()) {
      origin = "--secret-file";
      secret = api::read_secret_file(c.secret_file);
    } else if (c.key_file.empty() && api::is_loopback_endpoint(o->endpoint) && ::access(kDefaultSecretFile, R_OK) == 0) {
      origin = std::string("the local server's ") + kDefaultSecretFile;
      secret = api::read_secret_file(kDefaultSecretFile);
    }
    if (secret.empty() && c.key_file.empty())
      return "no credential: give --secret-file PATH (the server's --worker-secret-file, or its "
             "<data-dir>/keys/worker.secret) or --key-file PATH with --server-key KEY";
    if (!c.key_file.empty()) {
      origin = "--key-file";
      const api::CurveKeyPair own = api::read_key_file(c.key_file);
      o->public_key = own.public_key;
      o->secret_key = own.secret_key;
    } else {
      const api::CurveKeyPair own = api::derive_worker_keys(secret);
      o->public_key = own.public_key;
      o->secret_key = own.secret_key;
    }
    if (!c.server_key.empty()) {
      origin = "--server-key";
      o->server_key = api::read_public_key(c.server_key);
    } else if (!secret.empty()) {
      o->server_key = api::derive_server_keys(secret).public_key;
    } else {
      return "--key-file needs --server-key KEY|PATH (the server's public key)";
    }
  } catch (const std::exception& e) {
    return origin + ": " + e.what();
  }
  return "";
}

}  // namespace

int run_farm_worker_command(const std::vector<std::string>& args) {
  FarmWorkerOptions options;
  Credentials keys;
  std::string err = parse(args, &options, &keys);
  if (err.empty()) err = credentials(keys, &options);
  if (options.asset_cache_dir.empty()) options.asset_cache_dir = default_asset_cache_dir();
  if (!err.empty()) {
    std::cerr << "skyfarm-worker: " << err
              << "\nusage: skyfarm-worker [--connect URL] [--threads N] [--slots N] [--id NAME] [--secret-file PATH]"
                 "\n       [--key-file PATH --server-key KEY|PATH] (skyfarm-worker --help for more)\n";
    return 2;
  }
  install_termination_handlers();
  options.drain_flag = &termination_requested();
  try {
    FarmWorker worker(options);
    return worker.run();
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-worker: " << e.what() << " (" << options.endpoint << ")\n";
    return 1;
  }
}

}  // namespace skyfarm

// skyfarm-worker's default mode: the farm worker (farm_worker.h).
#include <cstdlib>
#include <iostream>
#include <optional>

#include "worker/farm_worker.h"
#include "worker/signals.h"

namespace skyfarm {

const char* const kFarmWorkerUsage =
    "  [--connect URL] [--threads N] [--slots N] [--token SECRET] [--id NAME]\n"
    "                                (default) a farm worker: connect to the server's broker\n"
    "                                (URL tcp://127.0.0.1:5555), render the units it hands out\n"
    "                                on N threads (0 = all cores) holding N+1 units (--slots);\n"
    "                                SIGTERM/SIGINT drain: finish the units, then leave.\n"
    "                                Each flag also reads SKYFARM_CONNECT, SKYFARM_THREADS,\n"
    "                                SKYFARM_SLOTS, SKYFARM_TOKEN (prefer it to --token), SKYFARM_ID\n";

namespace {

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

std::string apply(const std::string& flag, const std::string& value, FarmWorkerOptions* o) {
  if (flag == "--connect") {
    if (value.find("://") == std::string::npos) return "--connect: expected an endpoint like tcp://HOST:PORT, got '" + value + "'";
    o->endpoint = value;
    return "";
  }
  if (flag == "--threads") return read_count(flag, value, &o->threads);
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

std::string parse(const std::vector<std::string>& args, FarmWorkerOptions* o) {
  const std::pair<const char*, const char*> from_env[] = {{"--connect", "SKYFARM_CONNECT"}, {"--threads", "SKYFARM_THREADS"},
                                                          {"--slots", "SKYFARM_SLOTS"},     {"--token", "SKYFARM_TOKEN"},
                                                          {"--id", "SKYFARM_ID"}};
  for (const auto& [flag, name] : from_env)
    if (const auto v = env(name))
      if (std::string err = apply(flag, *v, o); !err.empty()) return std::string(name) + " (" + err + ")";
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
    if (std::string err = apply(flag, value, o); !err.empty()) return err;
  }
  return "";
}

}  // namespace

int run_farm_worker_command(const std::vector<std::string>& args) {
  FarmWorkerOptions options;
  if (const std::string err = parse(args, &options); !err.empty()) {
    std::cerr << "skyfarm-worker: " << err
              << "\nusage: skyfarm-worker [--connect URL] [--threads N] [--slots N] [--token SECRET] [--id NAME]"
                 "\n       (skyfarm-worker --help for more)\n";
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

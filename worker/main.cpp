// skyfarm-worker: the worker side of skyfarm.
//   skyfarm-worker [--connect tcp://HOST:PORT] [--threads N] [--slots N] [--secret-file PATH] ...
//                  the farm worker (the default mode: no command, or a first argument
//                  starting with "--"); each flag also reads SKYFARM_<FLAG>
//   skyfarm-worker render REQUEST.json -o OUT.exr [--png OUT.png] [--threads N]
//   skyfarm-worker probe PROBE.json|- [--threads N]
//   skyfarm-worker demo [DIR]
//   skyfarm-worker bench [paths|demo|memory|all] [--repeat N]
//   skyfarm-worker info REQUEST.json [--json]   the request's sun and optical depths
//   skyfarm-worker keygen PATH                  a CURVE key pair (PATH, PATH.pub)
//   skyfarm-worker --help | --version
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "api/curve_keys.h"
#include "api/field_error.h"
#include "api/render_request.h"
#include "worker/bench_command.h"
#include "worker/cli_io.h"
#include "worker/farm_worker.h"
#include "worker/render_command.h"
#include "worker/sky_report.h"

namespace {

constexpr const char* kUsage =
    "usage: skyfarm-worker [farm options]\n"
    "       skyfarm-worker <command> [options]\n"
    "\n"
    "farm worker (no command):\n"
    "%FARM%"
    "\n"
    "commands:\n"
    "  render REQUEST.json -o OUT.exr [--png OUT.png [--png-16bit]] [--threads N]\n"
    "         [--asset-cache DIR]    render a request on this machine (all cores by default);\n"
    "                                an objects[i].asset that is a file path (relative to\n"
    "                                REQUEST.json) is imported here and named by its id, an\n"
    "                                asset id is read from the farm worker's --asset-cache\n"
    "  probe PROBE.json [--threads N] spectral radiance in given directions, JSON on stdout\n"
    "                                (PROBE.json may be '-' for standard input)\n"
    "  demo [DIR]                    render the demo skies (a sunset equirect, a noon fisheye)\n"
    "                                to DIR/*.exr and *.png (DIR defaults to skyfarm-demo)\n"
    "  bench [paths|demo|memory|all] [--repeat N]\n"
    "                                the renderer's benchmarks, JSON lines on stdout\n"
    "  info REQUEST.json [--json]   sun position and optical depths of a render request\n"
    "                                (REQUEST.json may be '-' for standard input)\n"
    "  keygen PATH                   write a CURVE key pair for --key-file: PATH (the secret\n"
    "                                key, mode 0600) and PATH.pub (the public key, Z85)\n"
    "\n"
    "options:\n"
    "  --help      this text\n"
    "  --version   the skyfarm version\n";

std::string usage() {
  std::string text = kUsage;
  text.replace(text.find("%FARM%"), 6, skyfarm::kFarmWorkerUsage);
  return text;
}

int run_info(const std::vector<std::string>& args) {
  std::string path;
  bool json = false;
  for (const auto& a : args) {
    if (a == "--json") {
      json = true;
    } else if (path.empty()) {
      path = a;
    } else {
      std::cerr << "skyfarm-worker info: unexpected argument '" << a << "'\n" << usage();
      return 2;
    }
  }
  if (path.empty()) {
    std::cerr << "skyfarm-worker info: a request file is required\n" << usage();
    return 2;
  }
  std::string text, error;
  if (!skyfarm::read_input(path, &text, &error)) {
    std::cerr << "skyfarm-worker info: " << error << "\n";
    return 1;
  }
  try {
    const auto request = skyfarm::api::parse_render_request(text);
    const auto report = skyfarm::sky_report(request);
    std::cout << (json ? report.dump(2) + "\n" : skyfarm::format_sky_report(report));
    return 0;
  } catch (const skyfarm::api::ValidationError& e) {
    std::cerr << path << ": invalid request\n" << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-worker info: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h" || args[0] == "help")) {
    std::cout << usage();
    return 0;
  }
  if (!args.empty() && args[0] == "--version") {
    std::cout << "skyfarm " << SKYFARM_VERSION << "\n";
    return 0;
  }
  if (args.empty() || args[0].rfind("--", 0) == 0) return skyfarm::run_farm_worker_command(args);
  if (args[0] == "keygen") return skyfarm::api::run_keygen_command("skyfarm-worker", {args.begin() + 1, args.end()});
  const std::string command = args[0];
  args.erase(args.begin());
  if (command == "info") return run_info(args);
  if (command == "render") return skyfarm::run_render_command(args);
  if (command == "probe") return skyfarm::run_probe_command(args);
  if (command == "bench") return skyfarm::run_bench_command(args);
  if (command == "demo") return skyfarm::run_demo_command(args);
  std::cerr << "skyfarm-worker: unknown command '" << command << "'\n" << usage();
  return 2;
}

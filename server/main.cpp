// skyfarm-server: the render farm's HTTP API and ZeroMQ broker, with local
// workers by default (DESIGN §4).  See server_options.h for the flags.
#include <httplib.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <iostream>
#include <thread>

#include "common/render/parallel.h"
#include "server/broker.h"
#include "server/http_api.h"
#include "server/http_gate.h"
#include "server/job_service.h"
#include "server/local_workers.h"
#include "server/probe_router.h"
#include "server/probe_service.h"
#include "server/server_options.h"
#include "server/timelapse_service.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace skyfarm::server;
  ServerOptions options;
  if (const std::string err = parse_server_options({argv + 1, argv + argc}, &options); !err.empty()) {
    std::cerr << "skyfarm-server: " << err << "\n" << kServerUsage;
    return 2;
  }
  if (options.help) {
    std::cout << kServerUsage;
    return 0;
  }
  const std::size_t colon = options.listen.rfind(':');
  const std::string host = options.listen.substr(0, colon);
  int port = 0;
  try {
    port = std::stoi(options.listen.substr(colon + 1));
  } catch (const std::exception&) {
    std::cerr << "skyfarm-server: --listen: invalid port in '" << options.listen << "'\n";
    return 2;
  }
  if (options.token.empty() && !is_loopback(host)) {
    std::cerr << "skyfarm-server: refusing to listen on " << host
              << " without --token (loopback only unless a token protects the API)\n";
    return 2;
  }
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);

  try {
    ServiceLimits limits;
    limits.unit_timeout_s = options.unit_timeout_s;
    limits.max_active_jobs = options.max_active_jobs;
    limits.max_queue_units = options.max_queue_units;
    JobService service(options.data_dir, limits);
    // Path-traced probes share the workers with renders, ahead of them (probe_router.h).
    ProbeLimits probe_limits;
    probe_limits.unit_timeout_s = std::min(options.unit_timeout_s, kProbeUnitTimeoutCapS);
    auto probes = std::make_shared<ProbeService>(probe_limits);
    ProbeRouter router(*probes, service);
    TimelapseOptions timelapse_options;
    timelapse_options.ffmpeg = options.ffmpeg;
    timelapse_options.max_frames = options.max_timelapse_frames;
    TimelapseService timelapses(service, options.data_dir, timelapse_options);

    BrokerOptions broker_options;
    broker_options.endpoint = options.broker;
    broker_options.token = options.token;
    Broker broker(router, broker_options);
    broker.start();

    HttpOptions http_options;
    if (!options.token.empty()) http_options.token = options.token;
    http_options.max_body_bytes = static_cast<std::size_t>(options.max_body_bytes);
    http_options.probes = probes;
    http_options.probe_timeout = std::chrono::milliseconds(static_cast<long long>(options.probe_timeout_s * 1000.0));
    SkyServiceOptions sky;
    sky.table_cache_bytes = static_cast<std::size_t>(options.sky_cache_mb) << 20;
    sky.envmap_cache_bytes = static_cast<std::size_t>(options.envmap_cache_mb) << 20;
    http_options.sky = std::make_shared<SkyService>(sky);
    http_options.timelapses = &timelapses;
    HttpApi api(service, http_options);
    // Slow clients wait for their whole request in the gate, not on a thread (http_gate.h).
    GateOptions gate;
    gate.header_timeout = std::chrono::milliseconds(static_cast<long long>(options.header_timeout_s * 1000.0));
    gate.body_timeout = std::chrono::milliseconds(static_cast<long long>(options.body_timeout_s * 1000.0));
    gate.max_connections = options.max_connections;
    gate.max_buffered_body = http_options.max_body_bytes;
    GatedHttpServer http(gate);
    api.register_routes(http);
    // Port 0: any free port (printed below), for tests and side-by-side servers.
    const int bound_port = port == 0 ? http.bind_to_any_port(host.c_str()) : (http.bind_to_port(host.c_str(), port) ? port : -1);
    if (bound_port <= 0) {
      std::cerr << "skyfarm-server: cannot listen on " << options.listen << "\n";
      broker.stop();
      return 1;
    }
    std::thread http_thread([&] { http.listen_after_bind(); });

    LocalWorkerOptions local;
    local.worker_binary = options.worker_binary.empty() ? find_worker_binary(argv[0]) : options.worker_binary;
    local.endpoint = broker.bound_endpoint();
    local.count = options.local_workers < 0 ? skyfarm::resolve_thread_count(0) : options.local_workers;
    local.token = options.token;
    LocalWorkers workers(local);
    workers.start();

    std::cout << "skyfarm-server: HTTP on http://" << host << ":" << bound_port << ", broker on " << broker.bound_endpoint()
              << ", " << local.count << " local worker(s), data in " << options.data_dir << std::endl;
    while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(100));

    std::cout << "skyfarm-server: shutting down" << std::endl;
    probes->close();  // HTTP threads waiting for probes answer now
    workers.stop();
    broker.stop();
    http.stop();
    http_thread.join();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-server: " << e.what() << "\n";
    return 1;
  }
}

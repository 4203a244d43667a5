// skyfarm-server: the render farm's HTTP API and ZeroMQ broker, with local
// workers by default.  See server_options.h for the flags.
#include <httplib.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <thread>

#include "api/curve_keys.h"
#include "common/render/parallel.h"
#include "server/broker/broker.h"
#include "server/http/http_api.h"
#include "server/http/http_gate.h"
#include "server/jobs/job_service.h"
#include "server/broker/local_workers.h"
#include "server/probes/probe_router.h"
#include "server/probes/probe_service.h"
#include "server/server_options.h"
#include "server/timelapse/timelapse_service.h"
#include "server/assets/asset_store.h"
#include "server/assets/mesh_import_process.h"
#include "server/assets/volume_import_process.h"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

bool is_loopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// The broker's CURVE credentials and what the local workers get.
struct WorkerCredentials {
  skyfarm::api::CurveKeyPair server;
  std::vector<std::string> allowed_keys;  // the key derived from the shared secret
  std::string local_secret;               // handed to the local workers
};

// From the flags; throws std::runtime_error naming the flag (exit 2).
WorkerCredentials worker_credentials(const skyfarm::server::ServerOptions& o) {
  namespace api = skyfarm::api;
  WorkerCredentials c;
  std::string shared;
  const std::string keys_dir = o.data_dir + "/keys";
  if (!o.worker_secret_file.empty()) {
    try {
      shared = api::read_secret_file(o.worker_secret_file);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("--worker-secret-file: ") + e.what());
    }
  } else if (o.worker_keys.empty()) {
    if (!api::is_loopback_endpoint(o.broker))
      throw std::runtime_error("--broker " + o.broker +
                               " is reachable beyond this machine: give --worker-secret-file PATH (a shared secret) "
                               "or --worker-keys PATH (an allow-list of worker public keys) so that workers "
                               "must authenticate");
    try {
      shared = api::ensure_secret_file(keys_dir + "/worker.secret");
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("cannot keep the worker secret under --data-dir: ") + e.what());
    }
  } else {
    std::error_code ec;
    if (!std::filesystem::exists(o.worker_keys, ec))
      throw std::runtime_error("--worker-keys: " + o.worker_keys + ": no such file or folder");
  }
  if (!shared.empty()) {
    c.allowed_keys.push_back(api::derive_worker_keys(shared).public_key);
    c.local_secret = shared;
  } else {  // allow-list only: the local workers get a secret of this run
    c.local_secret = api::random_secret();
    c.allowed_keys.push_back(api::derive_worker_keys(c.local_secret).public_key);
  }
  if (!o.server_key_file.empty()) {
    try {
      c.server = api::read_key_file(o.server_key_file);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("--server-key-file: ") + e.what());
    }
  } else if (!shared.empty()) {
    c.server = api::derive_server_keys(shared);
  } else {  // an allow-list without a server key: one made once, kept with the data
    const std::string path = keys_dir + "/server.key";
    std::error_code ec;
    std::filesystem::create_directories(keys_dir, ec);
    if (!std::filesystem::exists(path, ec)) api::write_key_pair(path, api::generate_curve_keys());
    c.server = api::read_key_file(path);
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace skyfarm::server;
  if (argc >= 2 && std::string(argv[1]) == "keygen")
    return skyfarm::api::run_keygen_command("skyfarm-server", {argv + 2, argv + argc});
  // The mesh import's child process (server/assets/mesh_import_process.h), run by this server.
  if (argc >= 2 && std::string(argv[1]) == "import-mesh") return run_import_mesh_command({argv + 2, argv + argc});
  // The OpenVDB import's child process (server/assets/volume_import_process.h).
  if (argc >= 2 && std::string(argv[1]) == "import-volume")
    return run_import_volume_command({argv + 2, argv + argc});
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
  WorkerCredentials credentials;
  try {
    credentials = worker_credentials(options);
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-server: " << e.what() << "\n";
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
    limits.max_disk_bytes = options.max_disk_mb < 0 ? -1 : options.max_disk_mb << 20;
    limits.retention_hours = options.retention_hours;
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

    AssetStoreOptions asset_options;
    asset_options.import.command = {"/proc/self/exe", "import-mesh"};
    asset_options.volume_import.command = {"/proc/self/exe", "import-volume"};
    AssetStore assets(options.data_dir, asset_options);

    BrokerOptions broker_options;
    // Workers fetch the mesh and volume assets their units name (ASSET_GET, api/wire.h).
    broker_options.asset_file = [&assets](const std::string& id) { return assets.asset_file(id); };
    broker_options.endpoint = options.broker;
    broker_options.curve_secret_key = credentials.server.secret_key;
    broker_options.auth.allowed_keys = credentials.allowed_keys;
    broker_options.auth.keys_path = options.worker_keys;
    Broker broker(router, broker_options);
    broker.start();
    std::cout << "skyfarm-server: workers authenticate with CURVE; server public key "
              << credentials.server.public_key << std::endl;

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
    http_options.assets = &assets;
    http_options.extra_metrics = [&broker] {
      const BrokerStats s = broker.stats();
      return nlohmann::json{{"auth_failures", s.auth_failures},
                            {"results_refused", s.results_refused},
                            {"assets_served", s.assets_served},
                            {"assets_refused", s.assets_refused}};
    };
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
    local.worker_secret = credentials.local_secret;
    local.server_key = credentials.server.public_key;
    // Beside the store they fetch from: one copy per machine, gone with the data.
    local.asset_cache = (std::filesystem::path(options.data_dir) / "worker-assets").string();
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

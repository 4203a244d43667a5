// The farm worker: `skyfarm-worker --connect tcp://HOST:PORT`.
// It connects a DEALER to the server's broker, speaks api/wire.h, and renders
// the units it is sent with TileRenderer::render_unit, exactly as
// `skyfarm-worker render` does, so the farm's image is bit-identical (probe
// units as `skyfarm-worker probe` traces them, so the probe's answer is too).
//
// Threads
//   I/O thread     the thread calling run(): the only one touching the
//                  socket.  It sends READY, heartbeats every
//                  heartbeat_interval whatever the renderers are doing (a
//                  long unit never looks like a dead worker), queues UNITs
//                  for the render threads, forwards their RESULT / FAILED,
//                  and honours CANCEL.  Render threads wake it through a
//                  pipe, so a result leaves as soon as it is ready.
//   render threads `threads` of them (0 = all hardware threads); each
//                  renders one unit at a time, single-threaded (render_unit
//                  is sequential per unit; parallelism comes from units).
// Slots (the credit announced in READY): default threads + 1, so every
//   render thread is busy and one unit waits, which hides the round trip
//   between a result leaving and the next unit arriving.  A worker started
//   with --threads 1 (the server's embedded local workers) holds 2 units:
//   one rendering while the next arrives.
// Setups: a render's make_render_setup (a probe's make_probe_setup) is
//   cached per job id (worker/setup_cache.h: LRU of setup_cache_jobs = 4
//   jobs each for renders and probes; an entry is rebuilt if the job's
//   request text differs).  A request that does not parse, an out-of-range
//   unit or any exception while rendering is answered with FAILED and the
//   message.
// Probe units (UNIT kind "probe", worker/probe_unit.h) run on the same
//   render threads and slots as render units; READY advertises them with
//   the capability "probe": api::kProbeUnitsVersion.
// Mesh assets: a job whose objects name mesh assets gets them from a
//   MeshCache (worker/mesh_cache.h) shared by all jobs: memory, then the disk
//   cache asset_cache_dir, then the server (ASSET_GET, api/wire.h), asked
//   through the I/O thread (worker/asset_requests.h) and waited for up to
//   asset_timeout, twice.  A unit whose asset cannot be had FAILs with a
//   message naming the asset; one that got no answer in time is set up again
//   by the job's next unit, other errors are the job's on this worker.
// CANCEL: a queued unit is dropped; one being rendered finishes but its
//   result is not sent.
// Server lost (nothing heard for heartbeat_liveness x interval, or a
//   DISCONNECT): the socket is closed, the units of that session are
//   abandoned (the server requeues them), and after a back-off
//   (reconnect_initial doubling to reconnect_max, reset once the server
//   answers) a new socket connects and sends READY again.  REREGISTER (the
//   server forgot us) abandons the session's units and sends READY at once.
//   A fatal DISCONNECT (protocol version, worker id in use) ends run() with 1.
// Security: with server_key set the socket is a CURVE client (encrypted,
//   authenticated by the server's key; the server checks ours).  A server
//   that denies our key is never heard from: the worker logs why (socket
//   monitor) and keeps retrying with its back-off.
// Drain (request_drain(), or *drain_flag set by a SIGTERM handler): the
//   worker heartbeats "draining" so the server sends no more units, finishes
//   the units it holds, sends their results, then DISCONNECT, and run()
//   returns 0 (queued messages get drain_linger to leave).  Without a server
//   connection it returns 0 at once.
#pragma once
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm {

struct FarmWorkerOptions {
  std::string endpoint = "tcp://127.0.0.1:5555";
  int threads = 0;     // render threads; 0 = all hardware threads
  int slots = 0;       // units held at once (credit); 0 = threads + 1, plus up to 8 x that queued for short units (READY prefetch)
  std::string token;   // sent inside READY for older servers; no longer a credential (the broker ignores it)
  // CURVE (api/curve_keys.h): the server's public key and this worker's key
  // pair, Z85; server_key empty: the NULL mechanism (tests of the protocol only).
  std::string server_key;
  std::string public_key;
  std::string secret_key;
  std::string id;      // empty: hostname-pid-random
  std::chrono::milliseconds heartbeat_interval{1000};
  int heartbeat_liveness = 3;  // missed intervals before the server is declared lost
  std::chrono::milliseconds reconnect_initial{1000};
  std::chrono::milliseconds reconnect_max{32000};
  std::chrono::milliseconds drain_linger{2000};
  int setup_cache_jobs = 4;
  // Mesh assets (see above): the disk cache (empty: none) and its bound, the
  // bound on decoded meshes in memory, the wait for the server's answer.
  std::string asset_cache_dir;
  std::size_t asset_cache_bytes = std::size_t{2048} << 20;
  std::size_t asset_memory_bytes = std::size_t{1} << 30;
  std::chrono::milliseconds asset_timeout{60000};
  // Checked every loop tick (<= 100 ms) in addition to request_drain(); a
  // signal handler may set it (async-signal-safe).
  const std::atomic<bool>* drain_flag = nullptr;
  // Log lines; empty: standard error.
  std::function<void(std::string_view)> log;
};

// Counters since construction (thread-safe reads).
struct FarmWorkerStats {
  std::uint64_t sessions = 0;         // READY sent (first connection, reconnects, REREGISTER)
  std::uint64_t units_received = 0;
  std::uint64_t results_sent = 0;
  std::uint64_t failures_sent = 0;
  std::uint64_t cancels_received = 0;
  std::uint64_t results_dropped = 0;  // cancelled or abandoned units finished anyway
  std::uint64_t malformed = 0;        // undecodable or unexpected messages from the server
  std::uint64_t send_failures = 0;    // messages the socket would not queue
  std::uint64_t auth_failures = 0;    // CURVE handshakes the server refused or that failed
  std::uint64_t assets_requested = 0; // ASSET_GET sent
  std::uint64_t assets_received = 0;  // ASSET answers with the file
};

class FarmWorker {
 public:
  explicit FarmWorker(FarmWorkerOptions options = {});
  ~FarmWorker();
  FarmWorker(const FarmWorker&) = delete;
  FarmWorker& operator=(const FarmWorker&) = delete;

  // Serves until drained (0) or refused by the server (1).  Call once.
  int run();
  // Thread-safe and async-signal-safe.
  void request_drain();
  const std::string& id() const;
  int threads() const;
  int slots() const;
  FarmWorkerStats stats() const;
  // Tests: while paused the I/O loop neither reads nor heartbeats (a hung
  // process, as under SIGSTOP); render threads go on.
  void set_paused_for_testing(bool paused);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// hostname-pid-random, the default worker id.
std::string default_worker_id();

// `skyfarm-worker [--connect URL] [--threads N] [--slots N] [--token SECRET]
// [--id NAME] [--secret-file PATH] [--key-file PATH] [--server-key KEY|PATH]
// [--asset-cache DIR] [--asset-cache-mb N]`, each flag also read from
// SKYFARM_CONNECT, SKYFARM_THREADS, SKYFARM_SLOTS, SKYFARM_TOKEN, SKYFARM_ID,
// SKYFARM_WORKER_SECRET_FILE, SKYFARM_KEY_FILE, SKYFARM_SERVER_KEY,
// SKYFARM_ASSET_CACHE, SKYFARM_ASSET_CACHE_MB (a flag wins over its variable); SKYFARM_WORKER_SECRET
// holds the secret itself (it wins over a secret file).  Credentials
// (kFarmWorkerUsage): a key file wins for our own key pair, else the secret's
// derived pair; the server key is --server-key, else derived from the secret.
// With none, on a loopback endpoint, ./skyfarm-data/keys/worker.secret if
// readable.  Installs the SIGTERM/SIGINT handlers (signals.h) and runs a
// FarmWorker; returns its exit code (2 for bad arguments or no credential).
int run_farm_worker_command(const std::vector<std::string>& args);
extern const char* const kFarmWorkerUsage;

}  // namespace skyfarm

// The embedded default: skyfarm-server starts N local
// skyfarm-worker processes connected to its broker and keeps them running —
// a worker that exits unexpectedly is started again (after 1 s, doubling to
// 30 s while it keeps failing).  stop() sends SIGTERM (workers drain their
// units), waits up to 5 s, then SIGKILLs what is left.  Local workers get
// SIGTERM when the server process dies, however it dies (PR_SET_PDEATHSIG).
// Credentials travel in the environment, never argv (/proc/PID/cmdline is
// world-readable, /proc/PID/environ is not): SKYFARM_WORKER_SECRET (the
// shared worker secret) and SKYFARM_SERVER_KEY (the server's public key);
// the server's own SKYFARM_* credential variables are not passed on.
#pragma once
#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <sys/types.h>
#include <thread>
#include <vector>

namespace skyfarm::server {

struct LocalWorkerOptions {
  std::string worker_binary;  // path of skyfarm-worker
  std::string endpoint;       // the broker's bound endpoint
  int count = 0;
  int threads_each = 1;
  std::string worker_secret;  // SKYFARM_WORKER_SECRET of every worker
  std::string server_key;     // SKYFARM_SERVER_KEY (Z85 public key); empty: derived from the secret
  std::string asset_cache;    // --asset-cache of every worker (they share it); empty: the worker's default
};

class LocalWorkers {
 public:
  explicit LocalWorkers(LocalWorkerOptions options);
  ~LocalWorkers();
  void start();
  void stop();
  // Process ids of the running workers (for tests and /v1/workers).
  std::vector<pid_t> pids() const;

 private:
  pid_t spawn(int index);
  void supervise();

  LocalWorkerOptions options_;
  mutable std::mutex mu_;
  std::vector<pid_t> pids_;
  std::map<int, int> restarts_;  // per slot, guarded by mu_
  std::atomic<bool> stopping_{false};
  std::thread supervisor_;
};

// The skyfarm-worker next to this program (same folder, or ../worker/ in a
// build tree), or "skyfarm-worker" from PATH.
std::string find_worker_binary(const char* argv0);

}  // namespace skyfarm::server

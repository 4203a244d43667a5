#include "server/broker/local_workers.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string_view>

extern char** environ;

namespace skyfarm::server {

LocalWorkers::LocalWorkers(LocalWorkerOptions options) : options_(std::move(options)) {}

LocalWorkers::~LocalWorkers() { stop(); }

pid_t LocalWorkers::spawn(int index) {
  const std::string threads = std::to_string(options_.threads_each);
  // A restarted worker gets a new id: the broker refuses an id whose holder
  // has not yet missed its heartbeats, and the old process's may not have.
  const int restarts = restarts_[index]++;
  const std::string id = "local-" + std::to_string(::getpid()) + "-" + std::to_string(index) +
                         (restarts > 0 ? "-r" + std::to_string(restarts) : "");
  std::vector<std::string> args = {options_.worker_binary, "--connect", options_.endpoint, "--threads", threads,
                                   "--id", id};
  if (!options_.asset_cache.empty()) args.insert(args.end(), {"--asset-cache", options_.asset_cache});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Built before fork: the child of a threaded process may only exec.
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view var(*e);
    const bool credential = var.starts_with("SKYFARM_WORKER_SECRET") || var.starts_with("SKYFARM_KEY_FILE=") ||
                            var.starts_with("SKYFARM_SERVER_KEY") || var.starts_with("SKYFARM_TOKEN=");
    if (!credential) env.emplace_back(var);
  }
  if (!options_.worker_secret.empty()) env.push_back("SKYFARM_WORKER_SECRET=" + options_.worker_secret);
  if (!options_.server_key.empty()) env.push_back("SKYFARM_SERVER_KEY=" + options_.server_key);
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // A local worker dies with its server (even a SIGKILLed one), so none is
    // left behind knocking on a broker that no longer exists.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(0);
    ::execve(argv[0], argv.data(), envp.data());
    std::perror("skyfarm-server: cannot start the local worker");
    ::_exit(127);
  }
  return pid;
}

void LocalWorkers::start() {
  if (options_.count <= 0) return;
  {
    const std::lock_guard<std::mutex> lock(mu_);
    for (int i = 0; i < options_.count; ++i) pids_.push_back(spawn(i));
  }
  supervisor_ = std::thread([this] { supervise(); });
}

// Restarts workers that exit while the server runs (back-off per slot).
void LocalWorkers::supervise() {
  std::vector<std::chrono::seconds> backoff(static_cast<std::size_t>(options_.count), std::chrono::seconds(1));
  std::vector<std::chrono::steady_clock::time_point> restart_at(static_cast<std::size_t>(options_.count));
  while (!stopping_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::lock_guard<std::mutex> lock(mu_);
    const auto now = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < pids_.size(); ++i) {
      if (pids_[i] > 0) {
        int status = 0;
        if (::waitpid(pids_[i], &status, WNOHANG) == pids_[i]) {
          if (stopping_) break;
          std::fprintf(stderr, "skyfarm-server: local worker %d (pid %d) exited; restarting in %lld s\n",
                       static_cast<int>(i), static_cast<int>(pids_[i]), static_cast<long long>(backoff[i].count()));
          pids_[i] = 0;
          restart_at[i] = now + backoff[i];
          backoff[i] = std::min(backoff[i] * 2, std::chrono::seconds(30));
        }
      } else if (now >= restart_at[i] && !stopping_) {
        pids_[i] = spawn(static_cast<int>(i));
      }
    }
  }
}

void LocalWorkers::stop() {
  if (stopping_.exchange(true)) return;
  if (supervisor_.joinable()) supervisor_.join();
  const std::lock_guard<std::mutex> lock(mu_);
  for (pid_t pid : pids_)
    if (pid > 0) ::kill(pid, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  for (pid_t& pid : pids_) {
    while (pid > 0) {
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        pid = 0;
      } else if (std::chrono::steady_clock::now() > deadline) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        pid = 0;
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
  }
}

std::vector<pid_t> LocalWorkers::pids() const {
  const std::lock_guard<std::mutex> lock(mu_);
  return pids_;
}

std::string find_worker_binary(const char* argv0) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) self = fs::absolute(argv0, ec);
  const fs::path dir = self.parent_path();
  for (const fs::path& candidate : {dir / "skyfarm-worker", dir / ".." / "worker" / "skyfarm-worker"})
    if (fs::exists(candidate, ec)) return fs::canonical(candidate, ec).string();
  return "skyfarm-worker";
}

}  // namespace skyfarm::server

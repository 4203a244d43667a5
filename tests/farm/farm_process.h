// Test support: a real skyfarm-server (and skyfarm-worker processes) on
// loopback, started and killed like an operator would.
#pragma once
#include <httplib.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace skyfarm::testing {

inline pid_t spawn_process(const std::vector<std::string>& args, const std::filesystem::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A new, empty directory under the temporary folder: <prefix>_<name>_<pid>.
inline std::filesystem::path fresh_dir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / (prefix + "_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// The EXR bytes of `skyfarm-worker render` of `request`, rendered in `dir`
// (empty when the render failed): what a farm's image must equal.
inline std::string local_render_exr(const std::string& request, const std::filesystem::path& dir) {
  std::ofstream(dir / "request.json") << request;
  const std::string cmd = std::string(SKYFARM_WORKER_BINARY) + " render " + (dir / "request.json").string() +
                          " -o " + (dir / "local.exr").string() + " > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0) return std::string();
  return read_text(dir / "local.exr");
}

inline void kill_and_wait(pid_t pid, int sig = SIGKILL) {
  if (pid <= 0) return;
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

// A skyfarm-server on a free port; its broker endpoint and HTTP port are read
// from its first line of output.
class FarmServer {
 public:
  FarmServer(const std::filesystem::path& data_dir, int local_workers, const std::string& broker = "tcp://127.0.0.1:*",
             std::vector<std::string> extra = {})
      : secret_file_(data_dir / "keys" / "worker.secret"),
        log_(data_dir.parent_path() / (data_dir.filename().string() + "-server-" + std::to_string(next_log_index()) + ".log")) {
    std::filesystem::remove(log_);  // never read an older server's first line
    std::vector<std::string> args = {SKYFARM_SERVER_BINARY, "--listen", "127.0.0.1:0", "--broker", broker,
                                     "--local-workers", std::to_string(local_workers), "--data-dir", data_dir.string(),
                                     "--worker-binary", SKYFARM_WORKER_BINARY};
    args.insert(args.end(), extra.begin(), extra.end());
    pid_ = spawn_process(args, log_);
    const std::regex line(R"(HTTP on http://127\.0\.0\.1:(\d+), broker on (\S+),)");
    for (int i = 0; i < 200 && port_ == 0; ++i) {
      std::smatch m;
      const std::string text = read_text(log_);
      if (std::regex_search(text, m, line)) {
        port_ = std::stoi(m[1]);
        endpoint_ = m[2];
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    }
  }
  ~FarmServer() { kill_and_wait(pid_, SIGTERM); }
  static int next_log_index() {
    static int n = 0;
    return ++n;
  }
  FarmServer(const FarmServer&) = delete;
  FarmServer& operator=(const FarmServer&) = delete;

  bool ok() const { return port_ > 0; }
  int port() const { return port_; }
  const std::string& endpoint() const { return endpoint_; }
  // The worker secret a loopback server without credential flags keeps.
  const std::filesystem::path& secret_file() const { return secret_file_; }
  pid_t pid() const { return pid_; }
  std::string log() const { return read_text(log_); }
  void kill_now() {
    kill_and_wait(pid_, SIGKILL);
    pid_ = 0;
  }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(std::chrono::seconds(30));
    return c;
  }

  // Submits, returns the job id ("" on failure).
  std::string submit(const std::string& body) const {
    auto c = client();
    const auto res = c.Post("/v1/renders", body, "application/json");
    if (!res || res->status != 202) return "";
    return nlohmann::json::parse(res->body)["id"].get<std::string>();
  }
  // The status document, or {"state": "unreachable"} / {"state": "http <code>"}.
  nlohmann::json status(const std::string& id) const {
    auto c = client();
    const auto res = c.Get(("/v1/renders/" + id).c_str());
    if (!res) return {{"state", "unreachable"}, {"progress", {{"units_done", 0}}}};
    if (res->status != 200) return {{"state", "http " + std::to_string(res->status)}, {"progress", {{"units_done", 0}}}};
    return nlohmann::json::parse(res->body);
  }
  // Polls until the job is in a terminal state or the deadline passes.
  nlohmann::json wait(const std::string& id, std::chrono::seconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    nlohmann::json s;
    while (std::chrono::steady_clock::now() < deadline) {
      s = status(id);
      if (s.is_object()) {
        const std::string state = s["state"];
        if (state == "done" || state == "failed" || state == "cancelled") return s;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return s;
  }
  std::string download(const std::string& id, const std::string& file) const {
    auto c = client();
    const auto res = c.Get(("/v1/renders/" + id + "/" + file).c_str());
    return res && res->status == 200 ? res->body : std::string();
  }

 private:
  std::filesystem::path secret_file_;
  std::filesystem::path log_;
  pid_t pid_ = 0;
  int port_ = 0;
  std::string endpoint_;
};

// An external skyfarm-worker process (a "second machine") with the server's worker secret.
inline pid_t start_worker(const FarmServer& server, const std::filesystem::path& log, int threads = 1) {
  return spawn_process({SKYFARM_WORKER_BINARY, "--connect", server.endpoint(), "--threads", std::to_string(threads),
                        "--secret-file", server.secret_file().string()},
                       log);
}

}  // namespace skyfarm::testing

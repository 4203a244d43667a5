#include "server/assets/import_child.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace skyfarm::server {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxErrorChars = 300;

// The child's first stderr line, printable ASCII only, bounded.
std::string child_message(const fs::path& path) {
  std::string text;
  if (!read_whole_file(path.string(), &text)) return {};
  std::string out;
  for (char c : text) {
    if (c == '\n') break;
    if (out.size() >= kMaxErrorChars) break;
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  return out;
}

// A directory of its own under work_dir, removed when this goes.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& parent) {
    static std::atomic<unsigned> counter{0};
    fs::create_directories(parent);
    std::string templ = (fs::path(parent) / ("import-" + std::to_string(counter++) + "-XXXXXX")).string();
    if (!mkdtemp(templ.data())) throw std::runtime_error("cannot create a scratch directory under " + parent);
    path_ = templ;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

bool read_whole_file(const std::string& path, std::string* bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  *bytes = std::move(s).str();
  return true;
}

int parse_import_args(const std::vector<std::string>& args, std::string_view command,
                      const std::vector<ImportOption>& options, std::string* in, std::string* out) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    const auto option =
        std::find_if(options.begin(), options.end(), [&](const ImportOption& o) { return o.name == a; });
    if (option != options.end() && has_value) {
      if (!option->set(args[++i])) return 2;
    } else if (in->empty()) {
      *in = a;
    } else if (out->empty()) {
      *out = a;
    } else {
      std::cerr << command << ": unexpected argument '" << a << "'\n";
      return 2;
    }
  }
  return 0;
}

bool write_whole_file(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out.flush());
}

ImportChildResult run_import_child(std::string_view bytes, const std::vector<std::string>& child_args,
                                   const ImportChildOptions& options, std::string_view what) {
  ImportChildResult result;
  const std::string name(what);
  if (options.command.empty()) throw std::logic_error("run_import_child: no importer command");
  ScratchDir scratch(options.work_dir);
  const fs::path in = scratch.path() / "input";
  const fs::path out = scratch.path() / "output";
  const fs::path err = scratch.path() / "stderr";
  if (!write_whole_file(in.string(), bytes)) throw std::runtime_error("cannot write " + in.string());

  // Everything the child needs, made before fork().
  std::vector<std::string> args = options.command;
  args.insert(args.end(), child_args.begin(), child_args.end());
  args.push_back(in.string());
  args.push_back(out.string());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string err_path = err.string();
  const std::string dir = scratch.path().string();
  const int null_fd = open("/dev/null", O_RDWR | O_CLOEXEC);
  const int err_fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (null_fd < 0 || err_fd < 0) {
    if (null_fd >= 0) close(null_fd);
    if (err_fd >= 0) close(err_fd);
    throw std::runtime_error("cannot open the importer's stderr file");
  }
  const rlimit cpu{options.cpu_seconds, options.cpu_seconds + 1};
  const rlimit mem{options.memory_bytes, options.memory_bytes};
  const rlimit no_core{0, 0};

  const pid_t pid = fork();
  if (pid == 0) {
    // Child: async-signal-safe calls only until execv.
    dup2(null_fd, 0);
    dup2(null_fd, 1);
    dup2(err_fd, 2);
    syscall(SYS_close_range, 3u, ~0u, 0u);  // the server's sockets stay with the server
    setrlimit(RLIMIT_CPU, &cpu);
    setrlimit(RLIMIT_AS, &mem);
    setrlimit(RLIMIT_CORE, &no_core);
    if (chdir(dir.c_str()) != 0) _exit(126);  // relative names in the file resolve here, to nothing
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(null_fd);
  close(err_fd);
  if (pid < 0) throw std::runtime_error("cannot start the " + name + " importer: " + std::strerror(errno));

  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + options.timeout;
  bool timed_out = false;
  for (auto pause = std::chrono::microseconds(200);;) {
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) throw std::runtime_error("waitpid on the " + name + " importer failed");
    if (std::chrono::steady_clock::now() >= deadline) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      timed_out = true;
      break;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min<std::chrono::microseconds>(pause * 2, std::chrono::milliseconds(10));
  }

  if (timed_out) {
    result.error = "the " + name + " import took longer than " + std::to_string(options.timeout.count()) + " ms";
    return result;
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    result.error = sig == SIGXCPU || sig == SIGKILL
                       ? "the " + name + " import ran out of CPU time"
                       : "the " + name + " importer failed on this file (signal " + std::to_string(sig) + ")";
    return result;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 127 || code == 126 || code == 2)
      throw std::runtime_error("the " + name + " importer could not run (exit " + std::to_string(code) +
                               "): " + child_message(err));
    std::string message = child_message(err);
    result.error = message.empty() ? "the " + name + " importer failed on this file (exit " + std::to_string(code) + ")"
                                   : message;
    return result;
  }
  if (!read_whole_file(out.string(), &result.output)) {
    result.error = "the " + name + " importer wrote no " + name;
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace skyfarm::server

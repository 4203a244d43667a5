#include "server/timelapse/timelapse_video.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <thread>
#include <vector>

extern char** environ;

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

bool executable_file(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

std::optional<fs::path> search_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t colon = dirs.find(':', start);
    const std::string dir = dirs.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (executable_file(candidate)) return candidate;
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return std::nullopt;
}

// The last non-empty line ffmpeg wrote (its error), at most 300 characters.
std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

}  // namespace

FfmpegLookup find_ffmpeg(const std::string& configured) {
  FfmpegLookup out;
  if (configured.find('/') != std::string::npos) {
    if (executable_file(configured)) out.path = fs::path(configured);
    else out.reason = "ffmpeg '" + configured + "' (--ffmpeg / SKYFARM_FFMPEG) is not an executable file";
    return out;
  }
  const std::string name = configured.empty() ? "ffmpeg" : configured;
  out.path = search_path(name);
  if (!out.path)
    out.reason = "'" + name + "' was not found on PATH (install the Debian package ffmpeg, or give --ffmpeg PATH / SKYFARM_FFMPEG)";
  return out;
}

VideoResult encode_video(const fs::path& ffmpeg, const fs::path& frames_dir, int fps, const fs::path& out,
                         const fs::path& log, std::chrono::seconds timeout, const std::atomic<bool>& stop) {
  const fs::path tmp = out.parent_path() / (out.stem().string() + ".tmp.mp4");
  std::error_code ec;
  fs::remove(tmp, ec);
  std::vector<std::string> args = {ffmpeg.string(), "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
                                   "-framerate", std::to_string(fps), "-start_number", "0",
                                   "-i", (frames_dir / "frame_%05d.png").string(),
                                   "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
                                   "-movflags", "+faststart", tmp.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return {false, "cannot run ffmpeg '" + ffmpeg.string() + "': " + std::strerror(spawned)};

  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (true) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) return {false, std::string("waiting for ffmpeg failed: ") + std::strerror(errno)};
    const bool late = std::chrono::steady_clock::now() > deadline;
    if (late || stop) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      fs::remove(tmp, ec);
      return {false, late ? "ffmpeg took longer than " + std::to_string(timeout.count()) + " s and was stopped"
                          : std::string("the server stopped while ffmpeg ran")};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !fs::exists(tmp, ec)) {
    fs::remove(tmp, ec);
    const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                              : "was killed by signal " + std::to_string(WTERMSIG(status));
    const std::string why = last_line(log);
    return {false, "ffmpeg " + how + (why.empty() ? std::string() : ": " + why)};
  }
  fs::rename(tmp, out, ec);
  if (ec) return {false, "cannot rename the video to " + out.string() + ": " + ec.message()};
  return {true, ""};
}

}  // namespace skyfarm::server

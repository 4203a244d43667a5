#include "tests/support/webdriver.h"

#include <fcntl.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>
#include <vector>

namespace skyfarm::testing {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace std::chrono_literals;

// The W3C name of an element reference in JSON.
constexpr const char* kElementKey = "element-6066-11e4-a52e-4f735466cecf";

std::optional<fs::path> on_path(const std::vector<std::string>& names, const char* override_env) {
  if (const char* given = std::getenv(override_env); given && *given) {
    if (::access(given, X_OK) == 0) return fs::path(given);
    return std::nullopt;
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::vector<std::string> entries;
  for (std::string dir; std::getline(dirs, dir, ':');) entries.push_back(dir.empty() ? "." : dir);
  for (const auto& name : names)
    for (const auto& dir : entries)
      if (const fs::path p = fs::path(dir) / name; ::access(p.c_str(), X_OK) == 0) return p;
  return std::nullopt;
}

// A loopback port nobody listens on now (chromedriver binds it right after).
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    port = ntohs(addr.sin_port);
  ::close(fd);
  return port;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

std::optional<BrowserPrograms> WebDriver::find_programs() {
  const auto driver = on_path({"chromedriver"}, "SKYFARM_CHROMEDRIVER");
  const auto browser = on_path({"chromium", "chromium-browser", "google-chrome"}, "SKYFARM_CHROMIUM");
  if (!driver || !browser) return std::nullopt;
  return BrowserPrograms{*driver, *browser};
}

WebDriver::WebDriver(const BrowserPrograms& programs) {
  try {
    start_driver(programs);
    start_session(programs);
  } catch (const std::exception& e) {
    error_ = std::string(e.what()) + "\n--- chromedriver output ---\n" + read_file(log_path_);
    stop();
  }
}

WebDriver::~WebDriver() { stop(); }

void WebDriver::start_driver(const BrowserPrograms& programs) {
  port_ = free_port();
  if (port_ == 0) throw WebDriverError("no free loopback port for chromedriver");
  log_path_ = fs::temp_directory_path() / ("skyfarm_chromedriver_" + std::to_string(::getpid()) + "_" +
                                           std::to_string(port_) + ".log");
  const std::string driver = programs.chromedriver.string();
  const std::string port_arg = "--port=" + std::to_string(port_);
  pid_ = ::fork();
  if (pid_ < 0) throw WebDriverError("fork failed");
  if (pid_ == 0) {
    ::setpgid(0, 0);  // its own group: the teardown ends Chromium with it
    const int fd = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    ::execl(driver.c_str(), driver.c_str(), port_arg.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::setpgid(pid_, pid_);  // also here: no race with the child
  client_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
  client_->set_connection_timeout(2);
  client_->set_read_timeout(60);  // a new session starts a browser
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = 0;
      throw WebDriverError("chromedriver exited at start (status " + std::to_string(status) + ")");
    }
    if (auto res = client_->Get("/status"); res && res->status == 200) {
      const Json doc = Json::parse(res->body, nullptr, false);
      if (doc.is_object() && doc.value("value", Json::object()).value("ready", false)) return;
    }
    std::this_thread::sleep_for(50ms);
  }
  throw WebDriverError("chromedriver did not answer /status within 15 s");
}

void WebDriver::start_session(const BrowserPrograms& programs) {
  const Json options = {
      {"binary", programs.chromium.string()},
      {"args", {"--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,1600", "--no-first-run", "--no-default-browser-check"}}};
  const Json body = {{"capabilities",
                      {{"alwaysMatch",
                        {{"browserName", "chrome"},
                         {"goog:chromeOptions", options},
                         {"goog:loggingPrefs", {{"browser", "ALL"}}}}}}}};
  const Json value = command("POST", "/session", body);
  session_ = value.at("sessionId").get<std::string>();
}

void WebDriver::stop() {
  if (!session_.empty()) {
    try {
      command("DELETE", "/session/" + session_);  // Chromium exits
    } catch (...) {
    }
    session_.clear();
  }
  if (pid_ > 0) {
    ::kill(-pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + 3s;
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(20ms);
    ::kill(-pid_, SIGKILL);  // whatever is left of the group (a hung browser)
    ::waitpid(pid_, &status, 0);
    // The browser's processes are not our children: wait until the group is gone.
    const auto gone_by = std::chrono::steady_clock::now() + 3s;
    while (::kill(-pid_, 0) == 0 && std::chrono::steady_clock::now() < gone_by) std::this_thread::sleep_for(20ms);
    pid_ = 0;
  }
  client_.reset();
  if (!log_path_.empty()) {
    std::error_code ignored;
    fs::remove(log_path_, ignored);
  }
}

Json WebDriver::command(const std::string& method, const std::string& path, const Json& body) {
  if (!client_) throw WebDriverError("chromedriver is not running");
  const std::string text = body.is_null() ? std::string("{}") : body.dump();
  httplib::Result res = method == "GET"      ? client_->Get(path.c_str())
                        : method == "DELETE" ? client_->Delete(path.c_str())
                                             : client_->Post(path.c_str(), text, "application/json");
  if (!res) throw WebDriverError(method + " " + path + ": no answer from chromedriver (" + httplib::to_string(res.error()) + ")");
  const Json doc = Json::parse(res->body, nullptr, false);
  if (!doc.is_object() || !doc.contains("value"))
    throw WebDriverError(method + " " + path + ": HTTP " + std::to_string(res->status) + " " + res->body.substr(0, 300));
  const Json& value = doc["value"];
  if (res->status != 200 || (value.is_object() && value.contains("error")))
    throw WebDriverError(method + " " + path + ": " + value.value("error", std::string("HTTP error")) + ": " +
                         value.value("message", std::string()).substr(0, 600));
  return value;
}

void WebDriver::navigate(const std::string& url) { command("POST", "/session/" + session_ + "/url", {{"url", url}}); }

void WebDriver::set_window_size(int width, int height) {
  command("POST", "/session/" + session_ + "/window/rect", {{"width", width}, {"height", height}});
}

Element WebDriver::find(const std::string& css) {
  const Json value = command("POST", "/session/" + session_ + "/element", {{"using", "css selector"}, {"value", css}});
  return Element{value.at(kElementKey).get<std::string>()};
}

void WebDriver::clear(const Element& e) {
  command("POST", "/session/" + session_ + "/element/" + e.id + "/clear", Json::object());
}

void WebDriver::send_keys(const Element& e, const std::string& text) {
  command("POST", "/session/" + session_ + "/element/" + e.id + "/value", {{"text", text}});
}

void WebDriver::type(const std::string& css, const std::string& text) {
  const Element e = find(css);
  clear(e);
  send_keys(e, text);
}

void WebDriver::click(const Element& e) {
  command("POST", "/session/" + session_ + "/element/" + e.id + "/click", Json::object());
}

Json WebDriver::execute(const std::string& script, const Json& args) {
  return command("POST", "/session/" + session_ + "/execute/sync", {{"script", script}, {"args", args}});
}

bool WebDriver::wait_until(const std::string& script, std::chrono::milliseconds timeout,
                           std::chrono::milliseconds interval) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (execute(script) == Json(true)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(interval);
  }
}

std::string WebDriver::log() const {
  std::string out;
  if (!session_.empty() && client_) {
    // chromedriver's (non-W3C) log endpoint: the page's console messages and errors.
    const auto res = client_->Post(("/session/" + session_ + "/se/log").c_str(), R"({"type":"browser"})",
                                   "application/json");
    const Json doc = res ? Json::parse(res->body, nullptr, false) : Json();
    if (doc.is_object() && doc.contains("value") && doc["value"].is_array())
      for (const Json& entry : doc["value"])
        out += "console " + entry.value("level", std::string()) + ": " + entry.value("message", std::string()) + "\n";
  }
  return out + read_file(log_path_);
}

}  // namespace skyfarm::testing

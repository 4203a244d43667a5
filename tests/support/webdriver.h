// Test support: headless Chromium driven over the W3C WebDriver HTTP protocol
// (https://www.w3.org/TR/webdriver2/) through chromedriver, with
// cpp-httplib's client and nlohmann-json.  Only what the web page's tests
// need: one session, navigate, find elements, type, click, run scripts, wait.
//
//   WebDriver::find_programs()  chromedriver and a Chromium binary on PATH
//                               (env SKYFARM_CHROMEDRIVER / SKYFARM_CHROMIUM
//                               override), or nullopt: tests skip then
//   WebDriver(programs)         starts `chromedriver --port=N` (a free
//                               loopback port) in its own process group and a
//                               session with --headless=new --no-sandbox
//                               --disable-gpu --disable-dev-shm-usage;
//                               ok() / error() say whether that worked
//   ~WebDriver()                deletes the session (Chromium exits), then
//                               ends chromedriver's whole process group
//
// Every call throws WebDriverError with the driver's message when a command
// fails, so a test sees what went wrong; wait_until() returns false at its
// deadline instead (the test then asserts with its own message).
#pragma once
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace httplib {
class Client;
}

namespace skyfarm::testing {

struct BrowserPrograms {
  std::filesystem::path chromedriver;
  std::filesystem::path chromium;
};

class WebDriverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A W3C web element reference.
struct Element {
  std::string id;
};

class WebDriver {
 public:
  static std::optional<BrowserPrograms> find_programs();

  explicit WebDriver(const BrowserPrograms& programs);
  ~WebDriver();
  WebDriver(const WebDriver&) = delete;
  WebDriver& operator=(const WebDriver&) = delete;

  bool ok() const { return !session_.empty(); }
  // Why the driver or the session could not start (with chromedriver's log).
  const std::string& error() const { return error_; }

  void navigate(const std::string& url);
  // The browser window's outer size in CSS pixels (WebDriver "Set Window
  // Rect"); headless Chromium makes its viewport that size.
  void set_window_size(int width, int height);
  // The first element matching a CSS selector (throws "no such element").
  Element find(const std::string& css);
  void clear(const Element& e);
  void send_keys(const Element& e, const std::string& text);
  // Replaces an input's text by typing (clear, then keys).
  void type(const std::string& css, const std::string& text);
  void click(const Element& e);
  // `script` is a function body: `return ...;`, arguments as `arguments[i]`.
  nlohmann::json execute(const std::string& script, const nlohmann::json& args = nlohmann::json::array());
  // Polls `script` until it returns true or `timeout` passes.
  bool wait_until(const std::string& script, std::chrono::milliseconds timeout,
                  std::chrono::milliseconds interval = std::chrono::milliseconds(100));
  // The browser console and chromedriver's output so far, for failure messages.
  std::string log() const;

 private:
  nlohmann::json command(const std::string& method, const std::string& path, const nlohmann::json& body = {});
  void start_driver(const BrowserPrograms& programs);
  void start_session(const BrowserPrograms& programs);
  void stop();

  pid_t pid_ = 0;
  int port_ = 0;
  std::filesystem::path log_path_;
  std::unique_ptr<httplib::Client> client_;
  std::string session_;
  std::string error_;
};

}  // namespace skyfarm::testing

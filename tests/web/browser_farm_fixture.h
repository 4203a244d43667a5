// What the headless-Chromium tests of the web page share: a farm with one
// local worker (its own data folder) and Chromium on its page with app.js
// started; skipped without Chromium.  The browser goes before the server
// (members end in reverse order).
#pragma once
#include <chrono>
#include <optional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/farm/farm_process.h"
#include "tests/support/webdriver.h"

namespace skyfarm::testing {

inline constexpr const char* kChromiumMissing =
    "headless Chromium not installed: scripts/install-deps.sh --browser (Debian packages chromium, chromium-driver)";
// Deadlines only: each wait ends as soon as its condition holds.
inline constexpr std::chrono::seconds kPageTimeout{15};
inline constexpr std::chrono::seconds kRenderTimeout{60};

// A JavaScript string literal.
inline std::string js_string(const std::string& text) { return nlohmann::json(text).dump(); }

inline std::string text_of(WebDriver& driver, const std::string& css) {
  return driver.execute("const e = document.querySelector(arguments[0]); return e ? e.textContent : null;", {css})
      .get<std::string>();
}

class BrowserFarmTest : public ::testing::Test {
 protected:
  // Starts the farm (data under a fresh folder named by `prefix` and the test)
  // and the browser; the caller returns on a fatal failure or a skip.
  void start(const std::string& prefix) {
    const auto programs = WebDriver::find_programs();
    if (!programs) GTEST_SKIP() << kChromiumMissing;
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    server_.emplace(fresh_dir(prefix, name) / "data", 1);
    ASSERT_TRUE(server_->ok()) << server_->log();
    driver_.emplace(*programs);
    ASSERT_TRUE(driver_->ok()) << driver_->error();
  }

  void open_page() {
    driver_->navigate("http://127.0.0.1:" + std::to_string(server_->port()) + "/");
    ASSERT_TRUE(driver_->wait_until("return document.body.dataset.kind === 'render';", kPageTimeout))
        << "app.js did not start\n" << driver_->log();
  }

  std::optional<FarmServer> server_;
  std::optional<WebDriver> driver_;
};

}  // namespace skyfarm::testing

// The web page in headless Chromium (issue 7): a real skyfarm-server with one
// local worker on loopback, chromedriver driven over WebDriver
// (tests/support/webdriver.h).  The page is used like a person would: an
// invalid latitude is refused by the server and the page shows the problem
// next to the field; a small render typed in and submitted with Enter is
// shown live until its image has loaded and its state is done; the render
// list and the worker list show it and the worker.  Skipped (with the command
// that installs them) when Chromium or chromedriver is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "tests/farm/farm_process.h"
#include "tests/support/webdriver.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::FarmServer;
using testing::WebDriver;

constexpr const char* kSkipMessage =
    "headless Chromium not installed: scripts/install-deps.sh --browser (Debian packages chromium, chromium-driver)";
constexpr auto kPageTimeout = 15s;    // deadlines only: each wait ends as soon as its condition holds
constexpr auto kRenderTimeout = 60s;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_web_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A JavaScript string literal.
std::string js_string(const std::string& text) { return nlohmann::json(text).dump(); }

// Sets a datetime-local input the way its picker would (typing into one
// depends on the browser's locale), firing the events the page listens to.
void set_date_time(WebDriver& driver, const std::string& css, const std::string& value) {
  driver.execute("const e = document.querySelector(arguments[0]); e.value = arguments[1];"
                 "e.dispatchEvent(new Event('input', {bubbles: true}));",
                 {css, value});
}

std::string text_of(WebDriver& driver, const std::string& css) {
  return driver.execute("const e = document.querySelector(arguments[0]); return e ? e.textContent : null;", {css})
      .get<std::string>();
}

TEST(WebPage, RenderSubmittedFromThePageIsShownLiveListedAndDone) {
  const auto programs = WebDriver::find_programs();
  if (!programs) GTEST_SKIP() << kSkipMessage;
  const fs::path dir = fresh_dir("page");
  FarmServer server(dir / "data", 1);
  ASSERT_TRUE(server.ok()) << server.log();
  WebDriver driver(*programs);
  ASSERT_TRUE(driver.ok()) << driver.error();
  const std::string page = "http://127.0.0.1:" + std::to_string(server.port()) + "/";

  driver.navigate(page);
  ASSERT_TRUE(driver.wait_until("return document.body.dataset.kind === 'render';", kPageTimeout))
      << "app.js did not start\n" << driver.log();

  // The server's 400 problem, shown next to the field it names; no job made.
  driver.type("#latitude", "95");
  driver.click(driver.find("#submit"));
  ASSERT_TRUE(driver.wait_until("const e = document.querySelector('#latitude-error');"
                                "return !e.hidden && e.textContent.includes('location.latitude_deg');",
                                kPageTimeout))
      << driver.log();
  EXPECT_EQ(driver.execute("return document.querySelector('#latitude').getAttribute('aria-invalid');"), "true");
  EXPECT_FALSE(driver.execute("return document.querySelector('#form-problem').hidden;").get<bool>());
  EXPECT_EQ(nlohmann::json::parse(server.client().Get("/v1/renders")->body)["total"], 0);

  // A small render: Paris at 13:50 local time (UTC+2 in June), 32x16; 256
  // samples (16 passes, about a second of work) so that it is still running
  // when the page subscribes to its events.
  driver.type("#latitude", "48.85");
  driver.type("#longitude", "2.35");
  set_date_time(driver, "#time-local", "2021-06-21T13:50");
  driver.type("#time-zone", "Europe/Paris");
  EXPECT_EQ(driver.execute("return document.querySelector('#time-preview').value;"), "2021-06-21T13:50:00+02:00");
  driver.type("#width", "32");
  driver.type("#height", "16");
  driver.type("#spp", "256");
  driver.send_keys(driver.find("#spp"), "\xEE\x80\x87");  // U+E007 Enter: the keyboard submits the form

  const bool shown = driver.wait_until(
      "const img = document.querySelector('#job-image');"
      "return document.querySelector('#job-state').textContent === 'done' && img.complete && img.naturalWidth > 0;",
      kRenderTimeout);
  const std::string id = text_of(driver, "#job-id");
  ASSERT_TRUE(shown) << "render " << id << " state '" << text_of(driver, "#job-state") << "', image note '"
                     << text_of(driver, "#job-image-note") << "'\n" << driver.log();
  ASSERT_FALSE(id.empty());
  EXPECT_EQ(driver.execute("return location.hash;"), "#render=" + id);
  EXPECT_EQ(driver.execute("const i = document.querySelector('#job-image'); return [i.naturalWidth, i.naturalHeight];"),
            nlohmann::json::array({32, 16}));
  EXPECT_EQ(driver.execute("return document.querySelector('#job-progress').value;"), 1);
  EXPECT_TRUE(driver.execute("return document.querySelector('#job-cancel').disabled;").get<bool>());
  // The error-vs-time plot has the job's history (one point per merged pass).
  EXPECT_GE(driver.execute("return document.querySelectorAll('#job-plot circle').length;").get<int>(), 2);
  // It followed the job's event stream, and the image was fetched again after events.
  const nlohmann::json fetched = driver.execute(
      "return performance.getEntriesByType('resource').map(e => new URL(e.name).pathname + new URL(e.name).search);");
  std::string events_path = "/v1/renders/" + id + "/events";
  int last_image_event = 0;
  bool subscribed = false;
  for (const auto& url : fetched) {
    const std::string u = url.get<std::string>();
    subscribed = subscribed || u == events_path;
    const std::string image = "/v1/renders/" + id + "/image.png?event=";
    if (u.starts_with(image)) last_image_event = std::max(last_image_event, std::stoi(u.substr(image.size())));
  }
  EXPECT_TRUE(subscribed) << fetched.dump();
  EXPECT_GT(last_image_event, 1) << "the image was not reloaded on events: " << fetched.dump();

  // The farm agrees: that job, with the request the form described.
  const nlohmann::json status = server.status(id);
  EXPECT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(status["progress"]["samples_per_pixel"], 256);

  // The render list (refreshed by the page) has the job, done; the worker list a worker.
  const std::string row = js_string("#jobs-body tr[data-key=\"" + id + "\"]");
  EXPECT_TRUE(driver.wait_until("const row = document.querySelector(" + row + ");"
                                "return !!row && row.cells[1].textContent === 'done';",
                                kPageTimeout))
      << driver.log();
  EXPECT_TRUE(driver.wait_until("return document.querySelectorAll('#workers-body tr').length >= 1;", kPageTimeout))
      << driver.log();
  const std::string worker_cores = driver.execute("return document.querySelector('#workers-body tr').cells[1].textContent;");
  EXPECT_NE(worker_cores, "–") << "the worker row shows its cores";

  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  EXPECT_EQ(log.find("Content Security Policy"), std::string::npos) << log;
}

}  // namespace
}  // namespace skyfarm

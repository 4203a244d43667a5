// The web page as an operator's console, in headless Chromium against a real
// skyfarm-server with one local worker (as web_page_test.cpp): renders listed
// by name (or a description of place and time) with place, time, method, a
// thumbnail and progress in samples per pixel; the state filter hides the
// others; selecting one shows the request it made; Duplicate puts it into the
// form and the JSON editor, Re-submit sends it again as it is; the Drain
// button drains a worker through its route and Resume undoes it; the Render
// button is in view without scrolling and no label is clipped at 1280x720
// and 1920x1080.  Skipped (with the command that installs them) when
// Chromium or chromedriver is missing.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "tests/web/browser_farm_fixture.h"

namespace skyfarm {
namespace {

using namespace std::chrono_literals;
using testing::FarmServer;
using testing::WebDriver;
using testing::js_string;
using testing::kPageTimeout;
using testing::kRenderTimeout;
using testing::text_of;


// A small named path-traced render over Ithaca (done in well under a second).
constexpr const char* kNamed = R"({"name": "Alpha sunset over the lake",
  "location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
  "time": "2013-05-27T20:25:00-04:00",
  "camera": {"projection": "fisheye", "width": 16, "height": 16},
  "quality": {"samples_per_pixel": 4}})";
// An unnamed one that is cancelled at once (many passes: it is still running then).
constexpr const char* kCancelled = R"({"location": {"latitude_deg": 48.85, "longitude_deg": 2.35},
  "time": "2021-06-21T13:50:00+02:00",
  "camera": {"projection": "equirectangular", "width": 32, "height": 16},
  "quality": {"samples_per_pixel": 65536}})";

std::string row_of(const std::string& id) { return js_string("#jobs-body tr[data-key=\"" + id + "\"]"); }

class WebConsole : public testing::BrowserFarmTest {
 protected:
  void SetUp() override { start("skyfarm_web_console"); }

  // Submits kNamed over HTTP and waits until it is done; its id.
  std::string named_render_done() {
    const std::string id = server_->submit(kNamed);
    EXPECT_FALSE(id.empty()) << server_->log();
    EXPECT_EQ(server_->wait(id, kRenderTimeout)["state"], "done");
    return id;
  }
};

TEST_F(WebConsole, ListShowsNamesFiltersByStateShowsTheRequestAndDuplicates) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;
  const std::string named = named_render_done();
  const std::string cancelled = server.submit(kCancelled);
  ASSERT_FALSE(cancelled.empty());
  auto client = server.client();
  ASSERT_EQ(client.Delete(("/v1/renders/" + cancelled).c_str())->status, 202);
  open_page();

  // The list: the name; the unnamed one described by its place and time;
  // place, time, method and camera on the line below; samples, not units.
  ASSERT_TRUE(driver.wait_until("const a = document.querySelector(" + row_of(named) + "); const b = document.querySelector(" +
                                    row_of(cancelled) + "); return !!a && !!b && b.cells[1].textContent === 'cancelled';",
                                kPageTimeout))
      << driver.log();
  const std::string named_row = "document.querySelector(" + row_of(named) + ")";
  const std::string cancelled_row = "document.querySelector(" + row_of(cancelled) + ")";
  EXPECT_EQ(driver.execute("return " + named_row + ".querySelector('.job-link').textContent;"),
            "Alpha sunset over the lake");
  EXPECT_EQ(driver.execute("return " + cancelled_row + ".querySelector('.job-link').textContent;"),
            "Sky over 48.85° N, 2.35° E, 2021-06-21 11:50 UTC");
  EXPECT_EQ(driver.execute("return " + named_row + ".querySelector('.job-meta').textContent;"),
            "42.44° N, 76.48° W · 2013-05-28 00:25 UTC · path · fisheye 16×16");
  EXPECT_EQ(driver.execute("return " + named_row + ".cells[2].textContent.trim();"), "4 of 4 spp");
  // The done render's thumbnail: the final PNG, 16 px wide (narrower than the thumbnail width asked for).
  EXPECT_TRUE(driver.wait_until("const img = " + named_row + ".querySelector('img.list-thumb');"
                                "return img.complete && img.naturalWidth === 16;",
                                kPageTimeout))
      << driver.log();
  const nlohmann::json fetched = driver.execute(
      "return performance.getEntriesByType('resource').map(e => new URL(e.name).pathname + new URL(e.name).search);");
  EXPECT_NE(fetched.dump().find("/v1/renders/" + named + "/image.png?width=96"), std::string::npos) << fetched.dump();

  // Filter by state: the others are hidden.
  driver.execute("const f = document.querySelector('#state-filter'); f.value = 'done';"
                 "f.dispatchEvent(new Event('change', {bubbles: true}));");
  EXPECT_FALSE(driver.execute("return " + named_row + ".hidden;").get<bool>());
  EXPECT_TRUE(driver.execute("return " + cancelled_row + ".hidden;").get<bool>());
  driver.execute("const f = document.querySelector('#state-filter'); f.value = 'cancelled';"
                 "f.dispatchEvent(new Event('change', {bubbles: true}));");
  EXPECT_TRUE(driver.execute("return " + named_row + ".hidden;").get<bool>());
  EXPECT_FALSE(driver.execute("return " + cancelled_row + ".hidden;").get<bool>());
  // Still so after the next refresh of the list.
  std::this_thread::sleep_for(2500ms);
  EXPECT_TRUE(driver.execute("return " + named_row + ".hidden;").get<bool>());
  driver.execute("const f = document.querySelector('#state-filter'); f.value = '';"
                 "f.dispatchEvent(new Event('change', {bubbles: true}));");
  EXPECT_FALSE(driver.execute("return " + named_row + ".hidden;").get<bool>());

  // Selecting it shows what it asked for: its canonical request with its name.
  driver.click(driver.find("#jobs-body tr[data-key=\"" + named + "\"] a.job-link"));
  ASSERT_TRUE(driver.wait_until("return document.querySelector('#job-id').textContent === " + js_string(named) +
                                    " && document.querySelector('#job-request').textContent.length > 0;",
                                kPageTimeout))
      << driver.log();
  const nlohmann::json status = server.status(named);
  nlohmann::json asked = status["request"];
  asked["name"] = "Alpha sunset over the lake";
  EXPECT_EQ(nlohmann::json::parse(text_of(driver, "#job-request")), asked);
  EXPECT_EQ(text_of(driver, "#job-name"), "Alpha sunset over the lake");

  // Duplicate: the form and the JSON editor take the request.
  driver.click(driver.find("#job-duplicate"));
  const auto value = [&](const std::string& css) {
    return driver.execute("return document.querySelector(arguments[0]).value;", {css}).get<std::string>();
  };
  EXPECT_EQ(value("#name"), "Alpha sunset over the lake");
  EXPECT_EQ(value("#latitude"), "42.44");
  EXPECT_EQ(value("#longitude"), "-76.48");
  EXPECT_EQ(value("#time-zone"), "Z");  // the canonical request has the time in UTC
  EXPECT_EQ(value("#time-local").substr(0, 16), "2013-05-28T00:25");
  EXPECT_EQ(value("#projection"), "fisheye");
  EXPECT_EQ(value("#width"), "16");
  EXPECT_EQ(value("#height"), "16");
  EXPECT_EQ(value("#spp"), "4");
  EXPECT_EQ(value("#method"), "path");
  EXPECT_EQ(nlohmann::json::parse(value("#request-json")), asked);
  EXPECT_TRUE(driver.execute("return document.querySelector('#json-editor').open;").get<bool>());
  // The form, submitted as duplicated, asks for the same render: the farm
  // answers it from its result cache with the same id.
  driver.execute("window.sentBodies = []; const send = window.fetch;"
                 "window.fetch = (url, options) => { if (options && options.body) sentBodies.push(options.body);"
                 "  return send(url, options); };");
  driver.click(driver.find("#submit"));
  ASSERT_TRUE(driver.wait_until("return sentBodies.length === 1 && location.hash === " + js_string("#render=" + named) + ";",
                                kPageTimeout))
      << driver.execute("return [location.hash, sentBodies];").dump() << "\n" << driver.log();
  EXPECT_EQ(nlohmann::json::parse(driver.execute("return sentBodies[0];").get<std::string>())["name"],
            "Alpha sunset over the lake");

  // Re-submit sends the request as it is (with its name): the same render again.
  driver.click(driver.find("#job-resubmit"));
  ASSERT_TRUE(driver.wait_until("return sentBodies.length === 2;", kPageTimeout)) << driver.log();
  EXPECT_EQ(nlohmann::json::parse(driver.execute("return sentBodies[1];").get<std::string>()), asked);
  EXPECT_EQ(nlohmann::json::parse(client.Get("/v1/renders")->body)["total"], 2);

  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

// A timelapse: listed by name; selecting it shows its request; Duplicate
// switches the form to a timelapse with its start, end and frames.
TEST_F(WebConsole, TimelapseIsListedByNameAndDuplicatesIntoTheForm) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;
  const auto res = server.client().Post("/v1/timelapses", R"({"name": "Paris afternoon", "method": "lut",
    "location": {"latitude_deg": 48.85, "longitude_deg": 2.35},
    "start": "2021-06-21T12:00:00+02:00", "end": "2021-06-21T14:00:00+02:00", "frames": 3,
    "camera": {"projection": "equirectangular", "width": 16, "height": 8}})", "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const std::string id = nlohmann::json::parse(res->body)["id"];
  open_page();
  const std::string row = "document.querySelector(" + js_string("#timelapses-body tr[data-key=\"" + id + "\"]") + ")";
  ASSERT_TRUE(driver.wait_until("return !!" + row + ";", kPageTimeout)) << driver.log();
  EXPECT_EQ(driver.execute("return " + row + ".querySelector('.job-link').textContent;"), "Paris afternoon");
  EXPECT_EQ(driver.execute("return " + row + ".querySelector('.job-meta').textContent;"),
            "48.85° N, 2.35° E · 2021-06-21 12:00 +02:00 to 2021-06-21 14:00 +02:00 · lut · equirectangular 16×8");
  driver.click(driver.find("#timelapses-body tr[data-key=\"" + id + "\"] a.job-link"));
  ASSERT_TRUE(driver.wait_until("return document.querySelector('#tl-request').textContent.length > 0 &&"
                                " !document.querySelector('#tl-duplicate').disabled;",
                                kPageTimeout))
      << driver.log();
  EXPECT_EQ(text_of(driver, "#tl-name"), "Paris afternoon");
  const nlohmann::json shown = nlohmann::json::parse(text_of(driver, "#tl-request"));
  EXPECT_EQ(shown["name"], "Paris afternoon");
  EXPECT_EQ(shown["frames"], 3);
  driver.click(driver.find("#tl-duplicate"));
  EXPECT_EQ(driver.execute("return document.body.dataset.kind;"), "timelapse");
  const auto value = [&](const std::string& css) {
    return driver.execute("return document.querySelector(arguments[0]).value;", {css}).get<std::string>();
  };
  EXPECT_EQ(value("#name"), "Paris afternoon");
  EXPECT_EQ(value("#time-local").substr(0, 16), "2021-06-21T12:00");
  EXPECT_EQ(value("#time-end").substr(0, 16), "2021-06-21T14:00");
  EXPECT_EQ(value("#time-zone"), "+02:00");
  EXPECT_EQ(value("#split-kind"), "frames");
  EXPECT_EQ(value("#split-value"), "3");
  EXPECT_EQ(value("#method"), "lut");
  EXPECT_EQ(nlohmann::json::parse(value("#request-json")), shown);
  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

TEST_F(WebConsole, DrainButtonDrainsTheWorkerAndResumeUndoesIt) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;
  open_page();
  ASSERT_TRUE(driver.wait_until("const b = document.querySelector('#workers-body tr button.drain');"
                                "return !!b && b.textContent === 'Drain';",
                                kPageTimeout))
      << driver.log();
  const std::string id = driver.execute("return document.querySelector('#workers-body tr').dataset.key;");
  driver.click(driver.find("#workers-body tr button.drain"));
  ASSERT_TRUE(driver.wait_until("const row = document.querySelector('#workers-body tr');"
                                "return row.dataset.draining === 'true' && row.querySelector('button').textContent === 'Resume';",
                                kPageTimeout))
      << driver.log();
  auto workers = [&] { return nlohmann::json::parse(server.client().Get("/v1/workers")->body)["workers"]; };
  ASSERT_EQ(workers().size(), 1u);
  EXPECT_EQ(workers()[0]["id"], id);
  EXPECT_EQ(workers()[0]["draining"], true);
  const nlohmann::json fetched = driver.execute(
      "return performance.getEntriesByType('resource').map(e => new URL(e.name).pathname);");
  EXPECT_NE(fetched.dump().find("/v1/workers/" + id + "/drain"), std::string::npos) << fetched.dump();

  driver.click(driver.find("#workers-body tr button.drain"));
  ASSERT_TRUE(driver.wait_until("const row = document.querySelector('#workers-body tr');"
                                "return row.dataset.draining === 'false' && row.querySelector('button').textContent === 'Drain';",
                                kPageTimeout))
      << driver.log();
  EXPECT_EQ(workers()[0]["draining"], false);
}

// At both window sizes: the Render button is on screen without scrolling,
// and no label, heading, legend, button or list cell is narrower than its
// text (scrollWidth <= clientWidth), with the lists filled.
TEST_F(WebConsole, RenderButtonInViewAndNoLabelClipped) {
  WebDriver& driver = *driver_;
  named_render_done();
  for (const auto& [width, height] : {std::pair{1280, 720}, std::pair{1920, 1080}}) {
    driver.set_window_size(width, height);
    open_page();
    ASSERT_TRUE(driver.wait_until("return document.querySelectorAll('#jobs-body tr').length === 1 &&"
                                  " document.querySelectorAll('#workers-body tr').length === 1;",
                                  kPageTimeout))
        << driver.log();
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const nlohmann::json viewport = driver.execute("return [innerWidth, innerHeight];");
    EXPECT_LE(viewport[1].get<int>(), height) << size;
    const nlohmann::json rect = driver.execute(
        "const r = document.querySelector('#submit').getBoundingClientRect();"
        "return [r.top, r.bottom, r.left, r.right, innerHeight, innerWidth];");
    EXPECT_GE(rect[0].get<double>(), 0.0) << size << " " << rect.dump();
    EXPECT_LE(rect[1].get<double>(), rect[4].get<double>()) << size << " " << rect.dump();
    EXPECT_LE(rect[3].get<double>(), rect[5].get<double>()) << size << " " << rect.dump();
    // It stays in view while the form scrolls by.
    driver.execute("window.scrollTo(0, 300);");
    const nlohmann::json scrolled = driver.execute(
        "const r = document.querySelector('#submit').getBoundingClientRect(); return [r.top, r.bottom, innerHeight];");
    EXPECT_GE(scrolled[0].get<double>(), 0.0) << size << " " << scrolled.dump();
    EXPECT_LE(scrolled[1].get<double>(), scrolled[2].get<double>()) << size << " " << scrolled.dump();
    driver.execute("window.scrollTo(0, 0);");
    const nlohmann::json clipped = driver.execute(
        "return [...document.querySelectorAll('label, legend, h1, h2, h3, th, td, button, summary, .job-link, .job-meta')]"
        ".filter((e) => e.offsetParent !== null && e.scrollWidth > e.clientWidth + 1)"
        ".map((e) => (e.id || e.tagName) + ': ' + e.textContent.trim().slice(0, 40) + ' ' + e.scrollWidth + '>' + e.clientWidth);");
    EXPECT_EQ(clipped, nlohmann::json::array()) << size;
    EXPECT_LE(driver.execute("return document.documentElement.scrollWidth;").get<int>(),
              driver.execute("return document.documentElement.clientWidth;").get<int>())
        << size << ": the page scrolls sideways";
  }
}

}  // namespace
}  // namespace skyfarm

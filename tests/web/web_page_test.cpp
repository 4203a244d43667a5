// The web page in headless Chromium: a real skyfarm-server with one
// local worker on loopback, chromedriver driven over WebDriver
// (tests/support/webdriver.h).  The page is used like a person would: an
// invalid latitude is refused by the server and the page shows the problem
// next to the field; a small render typed in and submitted with Enter is
// shown live until its image has loaded and its state is done; the render
// list and the worker list show it and the worker.  A small LUT timelapse
// chosen and submitted in the form is followed until every frame of the strip
// has loaded (exposed as the sequence is), plays (the shown frame changes),
// offers its contact sheet and its video (or, without ffmpeg, says why not)
// and is listed done.  "Reference balls" puts the three balls in the request,
// in front of the camera; the Clouds box adds a layer only when a type is
// chosen.  Skipped (with the command that installs them) when
// Chromium or chromedriver is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>

#include "server/timelapse/timelapse_video.h"
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

// Sets a datetime-local input or a select the way its picker would (typing
// into a datetime-local depends on the browser's locale), firing the events
// the page listens to.
void set_value(WebDriver& driver, const std::string& css, const std::string& value) {
  driver.execute("const e = document.querySelector(arguments[0]); e.value = arguments[1];"
                 "e.dispatchEvent(new Event('input', {bubbles: true}));"
                 "e.dispatchEvent(new Event('change', {bubbles: true}));",
                 {css, value});
}

// Each test: a farm with one local worker and headless Chromium on the page,
// app.js started (browser_farm_fixture.h); skipped without Chromium.
class WebPage : public testing::BrowserFarmTest {
 protected:
  void SetUp() override {
    start("skyfarm_web");
    if (IsSkipped() || HasFatalFailure()) return;
    open_page();
  }
};

TEST_F(WebPage, RenderSubmittedFromThePageIsShownLiveListedAndDone) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;

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
  // when the page subscribes to its events; "more samples where the noise
  // is" ticked.
  driver.type("#latitude", "48.85");
  driver.type("#longitude", "2.35");
  set_value(driver, "#time-local", "2021-06-21T13:50");
  driver.type("#time-zone", "Europe/Paris");
  EXPECT_EQ(driver.execute("return document.querySelector('#time-preview').value;"), "2021-06-21T13:50:00+02:00");
  driver.type("#width", "32");
  driver.type("#height", "16");
  driver.type("#spp", "256");
  driver.execute("document.querySelector('#adaptive').click();");  // variance-aware sample allocation
  // A lake: water with a light ripple (the roughness input opens with the material).
  EXPECT_TRUE(driver.execute("return document.querySelector('#ground-roughness').disabled;").get<bool>());
  set_value(driver, "#ground-material", "water");
  EXPECT_FALSE(driver.execute("return document.querySelector('#ground-roughness').disabled;").get<bool>());
  driver.type("#ground-roughness", "0.05");
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
  EXPECT_EQ(status["plan"]["adaptive"], true) << "the checkbox asked for it";
  EXPECT_EQ(status["plan"]["ground"]["material"], "water") << status["plan"].dump();
  EXPECT_EQ(status["plan"]["ground"]["roughness"], nlohmann::json::array({0.05, 0.05}));
  EXPECT_NEAR(status["progress"]["samples_per_pixel"].get<double>(), 256.0, 4.0) << "the mean over the pixels";

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

// "Reference balls" adds the three balls in front of the camera, along its
// yaw, to the request the page sends; the farm renders it to the end.
TEST_F(WebPage, ReferenceBallsAreSentInFrontOfTheCameraAndRendered) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;
  // The bodies the page posts, kept as sent.
  driver.execute("window.sentBodies = []; const send = window.fetch;"
                 "window.fetch = (url, options) => { if (options && options.body) sentBodies.push(options.body);"
                 "  return send(url, options); };");
  EXPECT_FALSE(driver.execute("return document.querySelector('#reference-balls').checked;").get<bool>());
  set_value(driver, "#projection", "perspective");
  driver.type("#altitude", "1.6");
  driver.type("#yaw", "90");  // east: the balls go 5 m east, the chrome ball to the north
  driver.type("#pitch", "-10");
  driver.type("#width", "32");
  driver.type("#height", "18");
  driver.type("#spp", "16");
  driver.click(driver.find("#reference-balls"));
  driver.click(driver.find("#submit"));

  const bool done = driver.wait_until(
      "const img = document.querySelector('#job-image');"
      "return document.querySelector('#job-state').textContent === 'done' && img.complete && img.naturalWidth > 0;",
      kRenderTimeout);
  const std::string id = text_of(driver, "#job-id");
  ASSERT_TRUE(done) << "render " << id << " state '" << text_of(driver, "#job-state") << "', problem '"
                    << text_of(driver, "#form-problem") << "'\n" << driver.log();
  const nlohmann::json sent = driver.execute("return sentBodies;");
  ASSERT_EQ(sent.size(), 1u) << sent.dump();
  const nlohmann::json objects = nlohmann::json::parse(sent[0].get<std::string>())["objects"];
  ASSERT_EQ(objects.size(), 3u) << sent.dump();
  EXPECT_EQ(objects[0]["material"], nlohmann::json::parse(R"({"name": "chrome", "roughness": 0})"));
  EXPECT_EQ(objects[1]["albedo"], 0.18);
  EXPECT_EQ(objects[2]["albedo"], 0.8);
  EXPECT_EQ(objects[0]["translate_m"], nlohmann::json::parse("[5, 1.3, 0.5]"));
  EXPECT_EQ(objects[1]["translate_m"], nlohmann::json::parse("[5, 0, 0.5]"));
  EXPECT_EQ(objects[2]["translate_m"], nlohmann::json::parse("[5, -1.3, 0.5]"));
  for (const auto& ball : objects) EXPECT_EQ(ball["scale"], 0.5) << ball.dump();
  EXPECT_EQ(server.status(id)["state"], "done");

  // Unticked, the next request has no objects.
  driver.click(driver.find("#reference-balls"));
  driver.click(driver.find("#submit"));
  ASSERT_TRUE(driver.wait_until("return sentBodies.length === 2;", kPageTimeout)) << driver.log();
  EXPECT_FALSE(nlohmann::json::parse(driver.execute("return sentBodies[1];").get<std::string>()).contains("objects"));

  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

// The Clouds box: off by default (the request has no "clouds"); a type, the
// coverage slider and a wind speed and direction make one layer, the wind
// sent the meteorological way.  Only the bodies are checked: the server
// admits them, rendering them is the renderer's business.
TEST_F(WebPage, CloudLayerIsSentOnlyWhenATypeIsChosen) {
  WebDriver& driver = *driver_;
  driver.execute("window.sentBodies = []; const send = window.fetch;"
                 "window.fetch = (url, options) => { if (options && options.body) sentBodies.push(options.body);"
                 "  return send(url, options); };");
  EXPECT_EQ(driver.execute("return document.querySelector('#cloud-type').value;").get<std::string>(), "");
  EXPECT_TRUE(driver.execute("return document.querySelector('#cloud-coverage').disabled;").get<bool>());
  driver.type("#width", "16");
  driver.type("#height", "8");
  driver.click(driver.find("#submit"));
  ASSERT_TRUE(driver.wait_until("return sentBodies.length === 1;", kPageTimeout)) << driver.log();
  EXPECT_FALSE(nlohmann::json::parse(driver.execute("return sentBodies[0];").get<std::string>()).contains("clouds"));

  set_value(driver, "#cloud-type", "stratocumulus");
  EXPECT_FALSE(driver.execute("return document.querySelector('#cloud-coverage').disabled;").get<bool>());
  EXPECT_EQ(driver.execute("return document.querySelector('#cloud-coverage').value;").get<std::string>(), "0.7");
  set_value(driver, "#cloud-coverage", "0.25");
  driver.type("#cloud-wind-speed", "8");
  driver.click(driver.find("#submit"));
  ASSERT_TRUE(driver.wait_until("return sentBodies.length === 2;", kPageTimeout)) << driver.log();
  const nlohmann::json clouds = nlohmann::json::parse(driver.execute("return sentBodies[1];").get<std::string>())["clouds"];
  EXPECT_EQ(clouds, nlohmann::json::parse(
                        R"({"layers": [{"type": "stratocumulus", "coverage": 0.25, "wind": {"speed_m_s": 8, "from_deg": 270}}]})"))
      << clouds.dump();
  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

TEST_F(WebPage, TimelapseSubmittedFromThePageFillsTheStripPlaysAndIsListedDone) {
  FarmServer& server = *server_;
  WebDriver& driver = *driver_;
  driver.click(driver.find("input[name='kind'][value='timelapse']"));
  ASSERT_TRUE(driver.wait_until("return document.body.dataset.kind === 'timelapse';", kPageTimeout)) << driver.log();
  EXPECT_FALSE(driver.execute("return document.querySelector('#time-end').offsetParent === null;").get<bool>())
      << "the end time is shown for a timelapse";

  // Four LUT frames of 32x16 over Paris, 12:00 to 15:00 local time, an hour apart.
  driver.type("#latitude", "48.85");
  driver.type("#longitude", "2.35");
  set_value(driver, "#time-local", "2021-06-21T12:00");
  set_value(driver, "#time-end", "2021-06-21T15:00");
  driver.type("#time-zone", "Europe/Paris");
  set_value(driver, "#split-kind", "frames");
  driver.type("#split-value", "4");
  driver.type("#width", "32");
  driver.type("#height", "16");
  set_value(driver, "#method", "lut");
  driver.click(driver.find("#submit"));

  // Done, and every thumbnail loaded from the done timelapse's own PNGs.
  const bool filled = driver.wait_until(
      "const items = [...document.querySelectorAll('#tl-strip li')];"
      "return document.querySelector('#tl-state').textContent === 'done' && items.length === 4 &&"
      "  items.every((li) => { const img = li.querySelector('img');"
      "    return li.dataset.exposure === 'sequence' && img.complete && img.naturalWidth > 0; });",
      kRenderTimeout);
  const std::string id = text_of(driver, "#tl-id");
  ASSERT_TRUE(filled) << "timelapse " << id << " state '" << text_of(driver, "#tl-state") << "', "
                      << text_of(driver, "#tl-summary") << "; strip: "
                      << driver.execute("return [...document.querySelectorAll('#tl-strip li')].map("
                                        "(li) => li.textContent + '/' + li.dataset.exposure);")
                             .dump()
                      << "\n" << driver.log();
  ASSERT_FALSE(id.empty());
  EXPECT_EQ(driver.execute("return location.hash;"), "#timelapse=" + id);
  EXPECT_EQ(driver.execute("return [...document.querySelectorAll('#tl-strip img')].map((i) => [i.naturalWidth, i.naturalHeight]);"),
            nlohmann::json::parse("[[32,16],[32,16],[32,16],[32,16]]"));
  // The thumbnails show the done timelapse's frame PNGs (the sequence's
  // exposure): the same pixels as the served files, drawn on a canvas.
  EXPECT_EQ(driver.execute(
                "const pixels = (img) => { const c = document.createElement('canvas');"
                "  c.width = img.naturalWidth; c.height = img.naturalHeight;"
                "  const g = c.getContext('2d'); g.drawImage(img, 0, 0);"
                "  return g.getImageData(0, 0, c.width, c.height).data.join(); };"
                "const served = (i) => new Promise((ok, fail) => { const img = new Image();"
                "  img.onload = () => ok(pixels(img)); img.onerror = fail; img.src = arguments[0] + i + '.png'; });"
                "const imgs = [...document.querySelectorAll('#tl-strip img')];"
                "return Promise.all(imgs.map((img, i) => served(i).then((p) => p === pixels(img))));",
                {"/v1/timelapses/" + id + "/frames/"}),
            nlohmann::json::parse("[true,true,true,true]"));
  EXPECT_EQ(text_of(driver, "#tl-summary"), "4 of 4 frames · 100 %");
  ASSERT_TRUE(driver.wait_until("const img = document.querySelector('#tl-frame');"
                                "return img.complete && img.naturalWidth === 32;",
                                kPageTimeout))
      << "the first frame is shown large\n" << driver.log();

  // Play: the shown frame moves on; Pause stops it.
  const std::string first_caption = text_of(driver, "#tl-frame-caption");
  // The first frame to arrive is shown (the fetches run in parallel).
  EXPECT_NE(first_caption.find(" of 4: 2021-06-21T1"), std::string::npos) << first_caption;
  driver.click(driver.find("#tl-play"));
  EXPECT_TRUE(driver.wait_until("return document.querySelector('#tl-frame-caption').textContent !== " +
                                    js_string(first_caption) + " && document.querySelector('#tl-seek').value !== '0';",
                                kPageTimeout))
      << "the shown frame did not change: " << text_of(driver, "#tl-frame-caption") << "\n" << driver.log();
  EXPECT_EQ(driver.execute("return document.querySelector('#tl-play').getAttribute('aria-pressed');"), "true");
  driver.click(driver.find("#tl-play"));
  EXPECT_EQ(driver.execute("return document.querySelector('#tl-play').getAttribute('aria-pressed');"), "false");

  // The files, fetched as the links point: the contact sheet always; the video
  // when ffmpeg is installed, else the status's reason on the page.
  const std::string base = "/v1/timelapses/" + id;
  const std::string fetch_link =
      "const a = document.querySelector(arguments[0]); if (a.hidden) return 'hidden';"
      "return fetch(a.href).then((r) => new URL(a.href).pathname + ' ' + r.status + ' ' + r.headers.get('Content-Type'));";
  EXPECT_EQ(driver.execute(fetch_link, {"#tl-sheet"}), base + "/contact_sheet.png 200 image/png");
  const auto answer = server.client().Get(("/v1/timelapses/" + id).c_str());
  ASSERT_TRUE(answer && answer->status == 200);
  const nlohmann::json status = nlohmann::json::parse(answer->body);
  if (server::find_ffmpeg("").path) {
    EXPECT_EQ(driver.execute(fetch_link, {"#tl-video"}), base + "/video.mp4 200 video/mp4") << status["video"].dump();
  } else {
    EXPECT_EQ(driver.execute(fetch_link, {"#tl-video"}), "hidden");
    EXPECT_EQ(text_of(driver, "#tl-files-note"), "No video: " + status["video"]["reason"].get<std::string>());
  }

  // The farm agrees: that timelapse, with the request the form described.
  EXPECT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(status["method"], "lut");
  EXPECT_EQ(status["frames"].size(), 4u);
  EXPECT_EQ(status["frames"][3]["time"], "2021-06-21T15:00:00+02:00");
  EXPECT_EQ(status["request"]["camera"]["width"], 32);

  // The timelapse list (refreshed by the page) has it, done.
  const std::string row = js_string("#timelapses-body tr[data-key=\"" + id + "\"]");
  EXPECT_TRUE(driver.wait_until("const row = document.querySelector(" + row + ");"
                                "return !!row && row.cells[1].textContent === 'done' && row.cells[2].textContent === '4 of 4';",
                                kPageTimeout))
      << driver.log();

  const std::string log = driver.log();
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  EXPECT_EQ(log.find("Content Security Policy"), std::string::npos) << log;
}

}  // namespace
}  // namespace skyfarm

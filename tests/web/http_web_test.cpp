// The web page's files over HTTP (server/http/http_web.h): served from the binary
// at / and /web/*, with their Content-Type, a strong ETag that If-None-Match
// turns into 304, Cache-Control no-cache, public even when the API needs a
// token; unknown files stay 404 problems.  And a static check of the page:
// nothing loaded from elsewhere, every element app.js looks up exists.
#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <thread>

#include "server/http/http_api.h"
#include "tests/server/http/fake_backend.h"
#include "tests/support/http_fixture.h"
#include "tests/support/test_files.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using skyfarm::testing::read_text;

const fs::path kWebDir = fs::path(SKYFARM_SOURCE_DIR) / "server" / "http" / "web";

class HttpWebTest : public testing::HttpFixture {
 protected:
  void start(HttpOptions options = {}) {
    serve(std::move(options));
  }

};

void expect_file(const httplib::Result& r, const std::string& file, const std::string& type) {
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << file;
  EXPECT_EQ(r->get_header_value("Content-Type"), type) << file;
  EXPECT_EQ(r->body, read_text(kWebDir / file)) << file << ": the binary embeds another version";
  EXPECT_EQ(r->get_header_value("Cache-Control"), "no-cache") << file;
  EXPECT_EQ(r->get_header_value("X-Content-Type-Options"), "nosniff") << file;
  EXPECT_TRUE(std::regex_match(r->get_header_value("ETag"), std::regex(R"("[0-9a-f]{16,}")")))
      << file << ": " << r->get_header_value("ETag");
}

TEST_F(HttpWebTest, PageAndAssetsAreServedWithTheirTypes) {
  start();
  auto c = client();
  const auto page = c.Get("/");
  expect_file(page, "index.html", "text/html; charset=utf-8");
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("default-src 'self'"), std::string::npos);
  expect_file(c.Get("/web/app.js"), "app.js", "text/javascript; charset=utf-8");
  expect_file(c.Get("/web/style.css"), "style.css", "text/css; charset=utf-8");
  const auto head = c.Head("/");
  ASSERT_TRUE(head);
  EXPECT_EQ(head->status, 200);
  EXPECT_TRUE(head->body.empty());
  EXPECT_EQ(head->get_header_value("ETag"), page->get_header_value("ETag"));
}

TEST_F(HttpWebTest, ETagRevalidationAnswers304) {
  start();
  auto c = client();
  std::set<std::string> tags;
  for (const char* path : {"/", "/web/app.js", "/web/style.css"}) {
    const auto first = c.Get(path);
    ASSERT_TRUE(first);
    const std::string etag = first->get_header_value("ETag");
    tags.insert(etag);
    const auto again = c.Get(path, {{"If-None-Match", etag}});
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 304) << path;
    EXPECT_TRUE(again->body.empty()) << path;
    EXPECT_EQ(again->get_header_value("ETag"), etag) << path;
    EXPECT_EQ(again->get_header_value("Cache-Control"), "no-cache") << path;
    const auto weak = c.Get(path, {{"If-None-Match", "\"other\", W/" + etag}});
    ASSERT_TRUE(weak);
    EXPECT_EQ(weak->status, 304) << path;
    const auto changed = c.Get(path, {{"If-None-Match", "\"0000000000000000\""}});
    ASSERT_TRUE(changed);
    EXPECT_EQ(changed->status, 200) << path;
    EXPECT_FALSE(changed->body.empty()) << path;
  }
  EXPECT_EQ(tags.size(), 3u) << "each file has its own entity tag";
}

TEST_F(HttpWebTest, UnknownFilesStay404ProblemsAndOtherMethods405) {
  start();
  auto c = client();
  for (const char* path : {"/web/nope.js", "/web/", "/web/../api/openapi.yaml", "/index.html", "/web/app.js/x"}) {
    const auto r = c.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path;
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << path;
    const nlohmann::json doc = nlohmann::json::parse(r->body);
    EXPECT_EQ(doc.at("status"), 404) << path;
    EXPECT_FALSE(doc.at("detail").get<std::string>().empty()) << path;
  }
  for (const char* path : {"/", "/web/app.js"}) {
    const auto r = c.Post(path, "x", "text/plain");
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 405) << path;
    EXPECT_EQ(r->get_header_value("Allow"), "GET, HEAD") << path;
  }
}

TEST_F(HttpWebTest, ThePageIsPublicWhenTheApiNeedsAToken) {
  HttpOptions o;
  o.token = "s3cret";
  start(o);
  auto c = client();
  for (const char* path : {"/", "/web/app.js", "/web/style.css"}) {
    const auto r = c.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 200) << path;
  }
  const auto api = c.Get("/v1/renders");
  ASSERT_TRUE(api);
  EXPECT_EQ(api->status, 401);
  const auto other = c.Get("/web/secret.js");
  ASSERT_TRUE(other);
  EXPECT_EQ(other->status, 401) << "only the embedded files are public";
}

// Static checks of the page's sources: it works offline (no other origin)
// and app.js looks up only elements that index.html has.
TEST(WebPageSources, LoadNothingFromElsewhereAndEveryLookedUpIdExists) {
  const std::string html = read_text(kWebDir / "index.html");
  const std::string js = read_text(kWebDir / "app.js");
  const std::string css = read_text(kWebDir / "style.css");
  ASSERT_FALSE(html.empty());
  EXPECT_NE(html.find(R"(src="/web/app.js")"), std::string::npos);
  EXPECT_NE(html.find(R"(href="/web/style.css")"), std::string::npos);
  const std::regex url(R"(https?://|//[a-z0-9-]+\.[a-z])", std::regex::icase);
  for (const auto& [name, text] : {std::pair{"index.html", html}, std::pair{"style.css", css}})
    EXPECT_FALSE(std::regex_search(text, url)) << name << " names another origin";
  std::string js_without_namespace = std::regex_replace(js, std::regex(R"("http://www\.w3\.org/2000/svg")"), "\"\"");
  EXPECT_FALSE(std::regex_search(js_without_namespace, url)) << "app.js names another origin";

  const std::regex lookup(R"re(\$\("#([A-Za-z0-9_-]+)\"\))re");
  int lookups = 0;
  for (auto it = std::sregex_iterator(js.begin(), js.end(), lookup); it != std::sregex_iterator(); ++it, ++lookups)
    EXPECT_NE(html.find("id=\"" + (*it)[1].str() + "\""), std::string::npos) << "#" << (*it)[1] << " is not in index.html";
  EXPECT_GT(lookups, 30);
  // Every input, select and text area has a label (for=id).
  const std::regex control(R"re(<(input|select|textarea)\b[^>]*\bid="([^"]+)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), control); it != std::sregex_iterator(); ++it) {
    const std::string id = (*it)[2];
    const bool radio = (*it)[0].str().find("type=\"radio\"") != std::string::npos;
    if (radio) continue;  // labelled by the <label> around it
    EXPECT_NE(html.find("for=\"" + id + "\""), std::string::npos) << "#" << id << " has no label";
  }
}

}  // namespace
}  // namespace skyfarm::server

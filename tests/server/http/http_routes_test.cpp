// The routes the server answers are the operations api/openapi.yaml lists,
// method and path template both ways (timelapses included); each route's
// httplib pattern matches its path with any segment in a {name} and nothing
// else; and the 405/OPTIONS answers (the fallback's Allow) name the method of
// every route.
#include "server/http/http_routes.h"

#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "server/http/http_api.h"
#include "server/http/http_openapi.h"
#include "server/jobs/job_service.h"
#include "server/timelapse/timelapse_service.h"
#include "server/assets/asset_store.h"
#include "tests/support/http_fixture.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

// The operations under `paths:` of the OpenAPI document, read from its layout
// (yamllint and Api.OpenApiLint keep it regular): top-level keys at column 0,
// path templates at 2 spaces, methods at 4.
std::set<Route> document_routes(std::string_view yaml) {
  static const std::regex kPath(R"(^  '?(/[^':]*)'?:\s*$)");
  static const std::regex kMethod(R"(^    (get|put|post|delete|options|head|patch|trace):)");
  std::set<Route> routes;
  std::istringstream in{std::string(yaml)};
  std::string line, path;
  bool in_paths = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != ' ' && line[0] != '#') in_paths = line.starts_with("paths:");
    if (!in_paths) continue;
    std::smatch m;
    if (std::regex_match(line, m, kPath)) {
      path = m[1];
    } else if (std::regex_search(line, m, kMethod) && !path.empty()) {
      std::string method = m[1];
      for (char& c : method) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      routes.insert({method, path});
    }
  }
  return routes;
}

std::string listed(const std::set<Route>& routes) {
  std::string text;
  for (const Route& r : routes) text += "\n  " + r.method + " " + r.path;
  return text;
}

// The path with every {name} given a value a request could carry.
std::string instantiate(std::string path) {
  for (std::size_t open; (open = path.find('{')) != std::string::npos;) {
    const std::size_t close = path.find('}', open);
    const std::string name = path.substr(open + 1, close - open - 1);
    path.replace(open, close - open + 1, name == "file" ? "app.js" : name == "n" ? "0" : "abc");
  }
  return path;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_routes_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

TEST(HttpRoutes, PatternsMatchTheirPathWithAnySegmentInEachName) {
  EXPECT_EQ(route_pattern("/v1/renders/{id}/image.exr"), R"(/v1/renders/([^/]+)/image\.exr)");
  EXPECT_EQ(route_pattern("/"), "/");
  const std::regex frame(route_pattern("/v1/timelapses/{id}/frames/{n}.png"));
  std::smatch m;
  const std::string path = "/v1/timelapses/a-b_1/frames/12.png";
  ASSERT_TRUE(std::regex_match(path, m, frame));
  EXPECT_EQ(m[1], "a-b_1");
  EXPECT_EQ(m[2], "12");
  for (const char* other : {"/v1/timelapses/a/frames/12xpng", "/v1/timelapses/a/b/frames/1.png",
                            "/v1/timelapses//frames/1.png", "/v1/timelapses/a/frames/1.exr"})
    EXPECT_FALSE(std::regex_match(std::string(other), frame)) << other;
  EXPECT_THROW(route_pattern("/v1/renders/{}"), std::invalid_argument);
  EXPECT_THROW(route_pattern("/v1/renders/{id"), std::invalid_argument);
}

TEST(HttpRoutes, TheDocumentIsReadWhole) {
  const std::set<Route> routes = document_routes(openapi_yaml());
  EXPECT_TRUE(routes.contains(Route{"POST", "/v1/renders"}));
  EXPECT_TRUE(routes.contains(Route{"GET", "/v1/timelapses/{id}/frames/{n}.exr"}));
  EXPECT_TRUE(routes.contains(Route{"GET", "/healthz"}));  // past `paths:`' sub-keys
  EXPECT_GE(routes.size(), 20u);
  EXPECT_EQ(document_routes("openapi: 3.0.3\npaths:\n  /a:\n    get:\n      x: 1\n  '/b/{id}':\n    delete: {}\n"
                            "components:\n  /c:\n    get:\n"),
            (std::set<Route>{{"GET", "/a"}, {"DELETE", "/b/{id}"}}));
}

// The server's routes, timelapses and assets included, and the document's operations.
class HttpRoutesServed : public testing::HttpFixture {
 protected:
  void SetUp() override {
    jobs_ = std::make_unique<JobService>(dir_);
    timelapses_ = std::make_unique<TimelapseService>(*jobs_, dir_);
    AssetStoreOptions asset_options;
    asset_options.import.command = {SKYFARM_SERVER_BINARY, "import-mesh"};
    assets_ = std::make_unique<AssetStore>(dir_.string(), asset_options);
    HttpOptions options;
    options.timelapses = timelapses_.get();
    options.assets = assets_.get();
    serve(std::move(options));
  }
  void TearDown() override {
    HttpFixture::TearDown();
    timelapses_.reset();
    jobs_.reset();
    fs::remove_all(dir_);
  }
  const fs::path dir_ = fresh_dir("served");
  std::unique_ptr<JobService> jobs_;
  std::unique_ptr<TimelapseService> timelapses_;
  std::unique_ptr<AssetStore> assets_;
};

TEST_F(HttpRoutesServed, TheServerAnswersExactlyTheDocumentsOperations) {
  const std::vector<Route>& added = api_->routes();
  const std::set<Route> served(added.begin(), added.end());
  EXPECT_EQ(served.size(), added.size()) << "a route added twice";
  const std::set<Route> documented = document_routes(openapi_yaml());
  std::set<Route> undocumented, unserved;
  for (const Route& r : served)
    if (!documented.contains(r)) undocumented.insert(r);
  for (const Route& r : documented)
    if (!served.contains(r)) unserved.insert(r);
  EXPECT_TRUE(undocumented.empty()) << "served, not in api/openapi.yaml:" << listed(undocumented);
  EXPECT_TRUE(unserved.empty()) << "in api/openapi.yaml, not served:" << listed(unserved);
}

TEST_F(HttpRoutesServed, OptionsNamesTheMethodOfEveryRoute) {
  auto c = client();
  for (const Route& r : api_->routes()) {
    const std::string path = instantiate(r.path);
    const auto res = c.Options(path.c_str());
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 204) << r.method << " " << r.path << ": " << res->body;
    const std::string allow = res->get_header_value("Allow");
    EXPECT_NE(allow.find(r.method), std::string::npos) << r.method << " " << r.path << ": Allow " << allow;
    if (r.method == "GET") {
      EXPECT_NE(allow.find("HEAD"), std::string::npos) << r.path << ": Allow " << allow;
    }
  }
}

}  // namespace
}  // namespace skyfarm::server

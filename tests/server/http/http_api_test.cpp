// The HTTP layer on a real httplib::Server (127.0.0.1, any port) against a
// fake backend: submit and idempotency, every error status as problem+json,
// the bad requests of api/examples/bad/, ids, paging, images with ETags,
// Server-Sent Events (order, Last-Event-ID, closing, abrupt clients, the
// stream cap), metrics, the bearer token and the OpenAPI document.  Plus the
// pure checks of http_checks.h.
#include "server/http/http_api.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>

#include "tests/support/test_files.h"
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "server/http/http_checks.h"
#include "server/http/http_metrics.h"
#include "tests/server/http/fake_backend.h"
#include "tests/support/http_fixture.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::FakeBackend;

using skyfarm::testing::kExamples;
using skyfarm::testing::read_text;

std::string good_request() { return read_text(kExamples / "noon_fisheye.json"); }

nlohmann::json json_of(const httplib::Result& r) { return nlohmann::json::parse(r->body); }

// status + problem+json with the RFC 9457 members.
void expect_problem(const httplib::Result& r, int status, const std::string& instance = "") {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  const nlohmann::json doc = json_of(r);
  EXPECT_TRUE(doc.at("type").is_string());
  EXPECT_TRUE(doc.at("title").is_string());
  EXPECT_EQ(doc.at("status"), status);
  EXPECT_FALSE(doc.at("detail").get<std::string>().empty());
  if (!instance.empty()) {
    EXPECT_EQ(doc.at("instance"), instance);
  }
}

// The first invalid field a 400 names.
std::string first_field(const httplib::Result& r) {
  const nlohmann::json doc = json_of(r);
  if (!doc.contains("errors") || doc["errors"].empty()) return "<no errors>";
  return doc["errors"][0].at("field").get<std::string>();
}

// A whole response with a Content-Length body has arrived (others end at close).
bool response_complete(const std::string& text) {
  const std::size_t end = text.find("\r\n\r\n");
  if (end == std::string::npos) return false;
  std::string head = text.substr(0, end);
  std::transform(head.begin(), head.end(), head.begin(), [](unsigned char c) { return std::tolower(c); });
  const std::size_t at = head.find("\r\ncontent-length:");
  if (at == std::string::npos) return false;
  const std::size_t length = std::stoul(head.substr(at + 17));
  return text.size() >= end + 4 + length;
}

// One request over a plain socket (what httplib::Client would not send);
// answers everything the server wrote until it closed or 3 s passed.
std::string raw_exchange(int port, const std::string& request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return "";
  }
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string out;
  char buf[4096];
  for (ssize_t n; !response_complete(out) && (n = ::recv(fd, buf, sizeof buf, 0)) > 0;)
    out.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return out;
}

int raw_status(const std::string& response) {
  if (response.size() < 12 || !response.starts_with("HTTP/1.1 ")) return -1;
  return std::stoi(response.substr(9, 3));
}

struct SseFrame {
  std::uint64_t id = 0;
  std::string event;
  nlohmann::json data;
};

std::vector<SseFrame> parse_sse(const std::string& text) {
  std::vector<SseFrame> frames;
  std::size_t start = 0;
  for (std::size_t end; (end = text.find("\n\n", start)) != std::string::npos; start = end + 2) {
    std::istringstream block(text.substr(start, end - start));
    SseFrame f;
    bool any = false;
    for (std::string line; std::getline(block, line);) {
      if (line.starts_with("id: ")) f.id = std::stoull(line.substr(4)), any = true;
      if (line.starts_with("event: ")) f.event = line.substr(7);
      if (line.starts_with("data: ")) f.data = nlohmann::json::parse(line.substr(6));
    }
    if (any) frames.push_back(std::move(f));
  }
  return frames;
}

HttpOptions test_options() {
  HttpOptions o;
  o.sse_keepalive = 100ms;
  o.max_concurrent_streams = 4;
  return o;
}

class HttpApiTest : public testing::HttpFixture {
 protected:
  void start(HttpOptions options = test_options()) {
    serve(std::move(options));
  }
  httplib::Result post(const std::string& body, httplib::Headers headers = {},
                       const std::string& type = "application/json") {
    return client().Post("/v1/renders", headers, body, type);
  }
  void expect_healthy() {
    auto r = client().Get("/healthz");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    EXPECT_EQ(json_of(r), nlohmann::json({{"status", "ok"}}));
  }
  // Waits until no event stream is open (the server noticed the peer left).
  bool streams_drain(std::chrono::milliseconds limit) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (api_->open_streams() > 0 && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(10ms);
    return api_->open_streams() == 0;
  }
  fs::path temp_file(const std::string& name, const std::string& content) {
    const fs::path dir = fs::temp_directory_path() / ("skyfarm_http_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary) << content;
    return dir / name;
  }

};

// --- Submit -------------------------------------------------------------------

TEST_F(HttpApiTest, SubmitAnswers202WithLocationAndLinks) {
  start();
  auto r = post(good_request());
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 202) << r->body;
  EXPECT_EQ(r->get_header_value("Location"), "/v1/renders/job-1");
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/json");
  const auto doc = json_of(r);
  EXPECT_EQ(doc["id"], "job-1");
  EXPECT_EQ(doc["state"], "queued");
  EXPECT_EQ(doc["from_cache"], false);
  EXPECT_EQ(doc["links"], nlohmann::json({{"self", "/v1/renders/job-1"},
                                          {"exr", "/v1/renders/job-1/image.exr"},
                                          {"png", "/v1/renders/job-1/image.png"},
                                          {"events", "/v1/renders/job-1/events"}}));
  const auto subs = backend_.submissions();
  ASSERT_EQ(subs.size(), 1u);
  EXPECT_EQ(subs[0].canonical, api::canonical_text(api::parse_render_request(good_request())));
  EXPECT_FALSE(subs[0].key.has_value());
}

TEST_F(HttpApiTest, IdempotencyKeyIsPassedReplayedAndConflictsAre422) {
  start();
  auto first = post(good_request(), {{"Idempotency-Key", "key-123"}});
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status, 202);
  auto again = post(good_request(), {{"Idempotency-Key", "key-123"}});
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 202);
  EXPECT_EQ(json_of(again)["id"], json_of(first)["id"]);
  EXPECT_EQ(json_of(again)["created"], false);
  EXPECT_EQ(again->get_header_value("Location"), first->get_header_value("Location"));
  const auto subs = backend_.submissions();
  ASSERT_EQ(subs.size(), 2u);
  EXPECT_EQ(subs[0].key, "key-123");

  auto other = post(read_text(kExamples / "sunset_equirect.json"), {{"Idempotency-Key", "key-123"}});
  expect_problem(other, 422, "/v1/renders");
  EXPECT_EQ(json_of(other)["type"], "urn:skyfarm:problem:idempotency-conflict");
}

TEST_F(HttpApiTest, BadIdempotencyKeysAre400NamingTheHeader) {
  start();
  for (const std::string& key : {std::string(256, 'k'), std::string("two words"), std::string("cl\xc3\xa9")}) {
    auto r = post(good_request(), {{"Idempotency-Key", key}});
    expect_problem(r, 400);
    EXPECT_EQ(first_field(r), "Idempotency-Key");
  }
  auto twice = post(good_request(), {{"Idempotency-Key", "a"}, {"Idempotency-Key", "b"}});
  expect_problem(twice, 400);
  auto longest = post(good_request(), {{"Idempotency-Key", std::string(255, '~')}});
  ASSERT_TRUE(longest);
  EXPECT_EQ(longest->status, 202);
  EXPECT_EQ(backend_.submissions().size(), 1u);
}

TEST_F(HttpApiTest, MediaTypeMustBeJson) {
  start();
  expect_problem(post(good_request(), {}, "text/plain"), 415);
  expect_problem(post(good_request(), {}, "application/x-www-form-urlencoded"), 415);
  expect_problem(post(good_request(), {}, "application/json; charset=iso-8859-1"), 415);
  const std::string no_type = raw_exchange(port_, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nConnection: close\r\n"
                                                  "Content-Length: 2\r\n\r\n{}");
  EXPECT_EQ(raw_status(no_type), 415) << no_type;
  for (const char* ok : {"application/json; charset=UTF-8", "Application/JSON", "application/json;charset=\"utf-8\""}) {
    auto r = post(good_request(), {}, ok);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 202) << ok;
  }
}

TEST_F(HttpApiTest, BodiesOverTheLimitAre413) {
  HttpOptions o = test_options();
  o.max_body_bytes = 64 * 1024;
  start(o);
  auto r = post(std::string(64 * 1024 + 1, ' '));
  expect_problem(r, 413);
  // Chunked: httplib 0.11 does not bound it, the handler does.
  const std::string chunk(16 * 1024, ' ');
  std::string request = "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
                        "Transfer-Encoding: chunked\r\n\r\n";
  for (int i = 0; i < 8; ++i) request += "4000\r\n" + chunk + "\r\n";
  request += "0\r\n\r\n";
  const std::string answer = raw_exchange(port_, request);
  EXPECT_EQ(raw_status(answer), 413) << answer.substr(0, 200);
  EXPECT_NE(answer.find("Connection: close"), std::string::npos);
  EXPECT_TRUE(backend_.submissions().empty());
  // Exactly at the limit is parsed (and rejected only as a request).
  auto at_limit = post(std::string(64 * 1024, ' '));
  expect_problem(at_limit, 400);
  expect_healthy();
}

TEST_F(HttpApiTest, BackendFailuresMapToTheirStatus) {
  start();
  backend_.fail_next_submit(std::make_exception_ptr(CapacityExceeded("64 jobs are active")));
  auto busy = post(good_request());
  expect_problem(busy, 429);
  EXPECT_FALSE(busy->get_header_value("Retry-After").empty());
  EXPECT_EQ(json_of(busy)["detail"], "64 jobs are active");

  backend_.fail_next_submit(std::make_exception_ptr(StorageError("disk full")));
  auto full = post(good_request());
  expect_problem(full, 507);
  EXPECT_NE(json_of(full)["detail"].get<std::string>().find("disk full"), std::string::npos);

  backend_.fail_next_submit(std::make_exception_ptr(InsufficientStorage("this render needs about 300 MiB")));
  auto no_room = post(good_request());
  expect_problem(no_room, 507);
  EXPECT_EQ(json_of(no_room)["type"], "urn:skyfarm:problem:insufficient-storage");
  EXPECT_EQ(json_of(no_room)["detail"], "this render needs about 300 MiB");

  backend_.fail_next_submit(std::make_exception_ptr(std::runtime_error("secret internals at 0xdead")));
  auto broken = post(good_request());
  expect_problem(broken, 500);
  EXPECT_EQ(broken->body.find("secret"), std::string::npos);
  EXPECT_FALSE(broken->has_header("EXCEPTION_WHAT"));

  backend_.fail_everything(std::make_exception_ptr(std::logic_error("boom")));
  expect_problem(client().Get("/v1/renders/job-1"), 500);
  expect_problem(client().Get("/v1/renders"), 500);
  expect_problem(client().Get("/metrics"), 500);
  expect_healthy();
}

// --- Bad requests -----------------------------------------------------------------

TEST_F(HttpApiTest, EveryBadExampleIs400ProblemNamingTheField) {
  start();
  const auto expected = nlohmann::json::parse(read_text(kExamples / "bad" / "expected_errors.json"));
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kExamples / "bad")) {
    const std::string name = entry.path().filename().string();
    if (name == "expected_errors.json") continue;
    SCOPED_TRACE(name);
    auto r = post(read_text(entry.path()));
    expect_problem(r, 400, "/v1/renders");
    const auto doc = json_of(r);
    EXPECT_EQ(doc["type"], "urn:skyfarm:problem:validation-error");
    ASSERT_TRUE(doc.contains("errors"));
    ASSERT_FALSE(doc["errors"].empty());
    const auto& e = doc["errors"][0];
    const std::string field = e.at("field");
    const std::string message = e.at("message");
    EXPECT_TRUE(e.at("rule").is_string());
    EXPECT_TRUE(e.at("value").is_string());
    EXPECT_TRUE(message.starts_with(field.empty() ? "(request)" : field)) << message;
    if (!name.starts_with("probe")) {  // probes are another request type: their errors differ here
      ASSERT_TRUE(expected.contains(name));
      EXPECT_EQ(message, expected[name].get<std::string>());
    }
    ++count;
  }
  EXPECT_GE(count, 100);
  EXPECT_TRUE(backend_.submissions().empty());
  expect_healthy();
}

TEST_F(HttpApiTest, JsonDepthOptionIsEnforcedBeforeParsing) {
  HttpOptions o = test_options();
  o.max_json_depth = 4;
  start(o);
  auto deep = post(R"({"camera": {"projection": [[[1]]]}})");
  expect_problem(deep, 400);
  EXPECT_EQ(json_of(deep)["errors"][0]["message"], "(request): JSON nested deeper than 4 levels");
  auto shallow = post(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "camera": {"projection": [["]]]]]]"]]}})");  // brackets in strings do not count
  expect_problem(shallow, 400);
  EXPECT_EQ(first_field(shallow), "camera.projection");
}

TEST_F(HttpApiTest, MalformedHttpAndOddMethodsGetProblems) {
  start();
  const std::string garbage = raw_exchange(port_, "NONSENSE\r\n\r\n");
  EXPECT_EQ(raw_status(garbage), 400) << garbage;
  EXPECT_NE(garbage.find("application/problem+json"), std::string::npos);
  const std::string trace = raw_exchange(port_, "TRACE /v1/renders HTTP/1.1\r\nHost: t\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(trace), 400) << trace;  // httplib 0.11 rejects methods it does not know
  const std::string huge_path = raw_exchange(
      port_, "GET /" + std::string(8000, 'a') + " HTTP/1.1\r\nHost: t\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(huge_path), 404) << huge_path.substr(0, 200);
  const std::string too_long = raw_exchange(
      port_, "GET /" + std::string(9000, 'a') + " HTTP/1.1\r\nHost: t\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(raw_status(too_long), 414) << too_long.substr(0, 200);
  expect_healthy();
}

TEST_F(HttpApiTest, OneKeepAliveConnectionSurvivesBadRequests) {
  start();
  backend_.add_job("job-1");
  httplib::Client c("127.0.0.1", port_);
  c.set_keep_alive(true);
  c.set_read_timeout(5);
  for (int round = 0; round < 3; ++round) {
    expect_problem(c.Post("/v1/renders", "{\"camera\": 1}", "application/json"), 400);
    expect_problem(c.Post("/v1/renders", good_request(), "text/plain"), 415);
    expect_problem(c.Post("/v1/renders", std::string(2 << 20, ' '), "application/json"), 413);
    expect_problem(c.Put("/v1/renders", "{}", "application/json"), 405);
    auto del = c.Delete("/v1/renders/job-1", "{}", "application/json");
    ASSERT_TRUE(del);
    EXPECT_EQ(del->status, 202);
  }
  auto ok = c.Get("/healthz");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
}

TEST_F(HttpApiTest, RequestsWithoutLengthOrWithChunkedBodies) {
  start();
  backend_.add_job("job-7");
  const auto t0 = std::chrono::steady_clock::now();
  const std::string del = raw_exchange(port_, "DELETE /v1/renders/job-7 HTTP/1.1\r\nHost: t\r\n\r\n");
  EXPECT_EQ(raw_status(del), 202) << del;
  const std::string empty = raw_exchange(port_, "POST /v1/renders HTTP/1.1\r\nHost: t\r\n"
                                                "Content-Type: application/json\r\n\r\n");
  EXPECT_EQ(raw_status(empty), 400) << empty;
  EXPECT_NE(empty.find("unexpected end of input"), std::string::npos);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s) << "a body-less request was waited for";
  const std::string body = good_request();
  std::ostringstream chunked;
  chunked << "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
          << "Transfer-Encoding: chunked\r\n\r\n"
          << std::hex << 10 << "\r\n" << body.substr(0, 10) << "\r\n"
          << std::hex << body.size() - 10 << "\r\n" << body.substr(10) << "\r\n0\r\n\r\n";
  const std::string accepted = raw_exchange(port_, chunked.str());
  EXPECT_EQ(raw_status(accepted), 202) << accepted;
  ASSERT_EQ(backend_.submissions().size(), 1u);
}

TEST_F(HttpApiTest, ExpectContinueIsRefusedBeforeTheUpload) {
  HttpOptions o = test_options();
  o.token = "t0ken";
  start(o);
  const std::string no_token = raw_exchange(port_, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Type: "
                                                   "application/json\r\nContent-Length: 5000\r\nExpect: 100-continue\r\n\r\n");
  EXPECT_EQ(raw_status(no_token), 401) << no_token;
  const std::string too_big = raw_exchange(port_, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nAuthorization: Bearer t0ken\r\n"
                                                  "Content-Type: application/json\r\nContent-Length: 5000000\r\n"
                                                  "Expect: 100-continue\r\n\r\n");
  EXPECT_EQ(raw_status(too_big), 413) << too_big;
  EXPECT_NE(too_big.find("application/problem+json"), std::string::npos);
  const std::string go_on = raw_exchange(port_, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nAuthorization: Bearer t0ken\r\n"
                                                "Content-Type: application/json\r\nContent-Length: 2\r\n"
                                                "Expect: 100-continue\r\nConnection: close\r\n\r\n{}");
  EXPECT_TRUE(go_on.starts_with("HTTP/1.1 100 Continue\r\n\r\nHTTP/1.1 400 ")) << go_on;
}

TEST_F(HttpApiTest, HeadRequestsGetHeadersOnly) {
  start();
  backend_.add_job("job-1");
  backend_.set_image("job-1", ImageFormat::kPng, {temp_file("head.png", "PNGDATA"), "\"e\"", false});
  auto c = client();
  auto png = c.Head("/v1/renders/job-1/image.png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->status, 200);
  EXPECT_EQ(png->get_header_value("ETag"), "\"e\"");
  EXPECT_TRUE(png->body.empty());
  auto events = c.Head("/v1/renders/job-1/events");
  ASSERT_TRUE(events);
  EXPECT_EQ(events->status, 200);
  EXPECT_TRUE(streams_drain(1s));
  auto health = c.Head("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
}

// --- Ids, routes, methods -------------------------------------------------------

TEST_F(HttpApiTest, BadIdsNeverReachTheBackend) {
  start();
  backend_.add_job("job-1");
  auto c = client();
  for (const std::string& id : {std::string(65, 'a'), std::string("a.b"), std::string("%2E%2E"),
                               std::string("job%201"), std::string("%00")}) {
    SCOPED_TRACE(id);
    for (const char* suffix : {"", "/image.exr", "/image.png", "/events"}) {
      auto r = c.Get("/v1/renders/" + id + suffix);
      expect_problem(r, 400);
      EXPECT_EQ(first_field(r), "id");
    }
    expect_problem(c.Delete("/v1/renders/" + id), 400);
  }
  for (const char* path : {"/v1/renders/../../etc/passwd", "/v1/renders/..%2F..%2Fetc%2Fpasswd",
                                 "/v1/renders/job-1/../job-1", "/v1/renders/", "/v1/renders/job-1/image.gif"}) {
    const std::string answer = raw_exchange(port_, std::string("GET ") + path + " HTTP/1.1\r\nHost: t\r\nConnection: close\r\n\r\n");
    EXPECT_EQ(raw_status(answer), 404) << path;
    EXPECT_NE(answer.find("application/problem+json"), std::string::npos);
  }
  const std::string id64(64, 'z');
  expect_problem(c.Get("/v1/renders/" + id64), 404);
  for (const std::string& seen : backend_.ids_seen()) EXPECT_TRUE(valid_job_id(seen)) << seen;
}

TEST_F(HttpApiTest, UnknownJobsAre404) {
  start();
  auto c = client();
  for (const char* suffix : {"", "/image.exr", "/image.png", "/events"})
    expect_problem(c.Get(std::string("/v1/renders/nope") + suffix), 404, std::string("/v1/renders/nope") + suffix);
  expect_problem(c.Delete("/v1/renders/nope"), 404);
  expect_problem(c.Get("/v1/nothing-here"), 404);
  expect_problem(c.Get("/favicon.ico"), 404);  // "/" is the web page (tests/web/)
}

TEST_F(HttpApiTest, WrongMethodsAre405WithAllow) {
  start();
  auto c = client();
  auto put = c.Put("/v1/renders", good_request(), "application/json");
  expect_problem(put, 405);
  EXPECT_EQ(put->get_header_value("Allow"), "GET, HEAD, POST");
  auto post_id = c.Post("/v1/renders/job-1", "{}", "application/json");
  expect_problem(post_id, 405);
  EXPECT_EQ(post_id->get_header_value("Allow"), "GET, HEAD, DELETE");
  expect_problem(c.Delete("/v1/workers"), 405);
  expect_problem(c.Patch("/v1/renders/job-1/events", "{}", "application/json"), 405);
  expect_problem(c.Post("/healthz", "", "application/json"), 405);
  auto options = c.Options("/v1/renders");
  ASSERT_TRUE(options);
  EXPECT_EQ(options->status, 204);
  EXPECT_EQ(options->get_header_value("Allow"), "GET, HEAD, POST");
  expect_problem(c.Post("/v1/unknown", "{}", "application/json"), 404);
}

// --- List, status, cancel, workers ------------------------------------------------

TEST_F(HttpApiTest, ListIsPagedNewestFirst) {
  start();
  for (int i = 1; i <= 5; ++i) backend_.add_job("j" + std::to_string(i));
  auto c = client();
  auto all = c.Get("/v1/renders");
  ASSERT_TRUE(all);
  EXPECT_EQ(all->status, 200);
  auto doc = json_of(all);
  EXPECT_EQ(doc["offset"], 0);
  EXPECT_EQ(doc["limit"], 20);
  EXPECT_EQ(doc["total"], 5);
  ASSERT_EQ(doc["renders"].size(), 5u);
  EXPECT_EQ(doc["renders"][0]["id"], "j5");
  auto page = c.Get("/v1/renders?offset=1&limit=2");
  doc = json_of(page);
  EXPECT_EQ(backend_.last_list_call(), std::make_pair(std::size_t{1}, std::size_t{2}));
  ASSERT_EQ(doc["renders"].size(), 2u);
  EXPECT_EQ(doc["renders"][0]["id"], "j4");
  EXPECT_EQ(doc["limit"], 2);
  EXPECT_EQ(json_of(c.Get("/v1/renders?limit=100"))["limit"], 100);
  const std::pair<const char*, const char*> bad[] = {
      {"limit=0", "limit"},       {"limit=101", "limit"},   {"limit=abc", "limit"}, {"limit=", "limit"},
      {"offset=-1", "offset"},    {"offset=1e3", "offset"}, {"offset=%201", "offset"},
      {"limit=5&limit=6", "limit"}, {"offset=99999999999999999999999", "offset"}};
  for (const auto& [query, field] : bad) {
    auto r = c.Get(std::string("/v1/renders?") + query);
    expect_problem(r, 400);
    EXPECT_EQ(first_field(r), field) << query;
  }
}

TEST_F(HttpApiTest, StatusAndCancel) {
  start();
  backend_.add_job("job-7", "running");
  auto c = client();
  auto status = c.Get("/v1/renders/job-7");
  ASSERT_TRUE(status);
  EXPECT_EQ(status->status, 200);
  EXPECT_EQ(json_of(status)["state"], "running");
  auto cancel = c.Delete("/v1/renders/job-7");
  ASSERT_TRUE(cancel);
  EXPECT_EQ(cancel->status, 202);
  EXPECT_EQ(json_of(cancel)["state"], "cancelled");
  EXPECT_EQ(backend_.cancelled(), std::vector<std::string>{"job-7"});
}

// ?purge=true removes a render (204, then 404); a timelapse's frame is a
// 409; anything but true or false is a 400 naming the parameter.
TEST_F(HttpApiTest, DeleteWithPurgeRemovesTheRender) {
  start();
  backend_.add_job("job-8", "done");
  backend_.add_job("frame-1", "done");
  auto c = client();
  auto bad = c.Delete("/v1/renders/job-8?purge=yes");
  ASSERT_TRUE(bad);
  expect_problem(bad, 400);
  EXPECT_NE(bad->body.find("purge"), std::string::npos) << bad->body;
  auto purged = c.Delete("/v1/renders/job-8?purge=true");
  ASSERT_TRUE(purged);
  EXPECT_EQ(purged->status, 204);
  expect_problem(c.Get("/v1/renders/job-8"), 404);
  expect_problem(c.Delete("/v1/renders/job-8?purge=true"), 404);
  expect_problem(c.Delete("/v1/renders/frame-1?purge=true"), 409);
  auto kept = c.Delete("/v1/renders/frame-1?purge=false");
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->status, 202);
  EXPECT_TRUE(backend_.cancelled() == std::vector<std::string>{"frame-1"});
}

// An expired render's images are 410 Gone; a cancelled render's are 409.
TEST_F(HttpApiTest, ExpiredImagesAreGoneAndCancelledOnesConflict) {
  start();
  backend_.add_job("job-old", "done");
  backend_.set_field("job-old", "expired", true);
  backend_.add_job("job-stop", "cancelled");
  auto gone = client().Get("/v1/renders/job-old/image.exr");
  expect_problem(gone, 410);
  EXPECT_NE(json_of(gone)["detail"].get<std::string>().find("retention"), std::string::npos);
  auto stopped = client().Get("/v1/renders/job-stop/image.png");
  expect_problem(stopped, 409);
  EXPECT_NE(json_of(stopped)["detail"].get<std::string>().find("cancelled"), std::string::npos);
}

TEST_F(HttpApiTest, WorkersAndHealth) {
  start();
  auto r = client().Get("/v1/workers");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(json_of(r)["workers"][0]["id"], "w1");
  expect_healthy();
}

// --- Images -------------------------------------------------------------------------

TEST_F(HttpApiTest, ImagesHaveETagsAnd304AndCacheControl) {
  start();
  backend_.add_job("job-1", "running");
  auto c = client();
  auto early = c.Get("/v1/renders/job-1/image.exr");
  expect_problem(early, 409);
  EXPECT_EQ(json_of(early)["type"], "urn:skyfarm:problem:image-not-ready");

  std::string exr_bytes(200000, '\0');
  for (std::size_t i = 0; i < exr_bytes.size(); ++i) exr_bytes[i] = static_cast<char>(i * 7);
  backend_.set_image("job-1", ImageFormat::kExr, {temp_file("preview.exr", exr_bytes), "\"job-1-8\"", false});
  auto r = c.Get("/v1/renders/job-1/image.exr");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/x-exr");
  EXPECT_EQ(r->get_header_value("ETag"), "\"job-1-8\"");
  EXPECT_EQ(r->get_header_value("Cache-Control"), "no-cache");
  EXPECT_TRUE(r->body == exr_bytes);

  auto same = c.Get("/v1/renders/job-1/image.exr", {{"If-None-Match", "\"x\", \"job-1-8\""}});
  ASSERT_TRUE(same);
  EXPECT_EQ(same->status, 304);
  EXPECT_TRUE(same->body.empty());
  EXPECT_EQ(same->get_header_value("ETag"), "\"job-1-8\"");
  auto changed = c.Get("/v1/renders/job-1/image.exr", {{"If-None-Match", "\"job-1-4\""}});
  ASSERT_TRUE(changed);
  EXPECT_EQ(changed->status, 200);

  backend_.set_image("job-1", ImageFormat::kPng, {temp_file("image.png", "PNGDATA"), "\"hash\"", true});
  auto png = c.Get("/v1/renders/job-1/image.png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->status, 200);
  EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(png->body, "PNGDATA");
  EXPECT_EQ(png->get_header_value("Cache-Control"), "public, max-age=31536000, immutable");
  auto png304 = c.Get("/v1/renders/job-1/image.png", {{"If-None-Match", "W/\"hash\""}});
  ASSERT_TRUE(png304);
  EXPECT_EQ(png304->status, 304);

  backend_.set_image("job-1", ImageFormat::kPng, {"/nonexistent/skyfarm.png", "\"gone\"", true});
  expect_problem(c.Get("/v1/renders/job-1/image.png"), 500);
}

// --- Server-Sent Events ------------------------------------------------------------

TEST_F(HttpApiTest, EventsArriveInOrderAndTheStreamClosesAfterDone) {
  start();
  backend_.add_job("job-1");
  for (const char* type : {"progress", "progress", "progress", "done"}) backend_.push_event("job-1", type);
  std::string text;
  httplib::Headers headers;
  std::string content_type;
  auto r = client().Get("/v1/renders/job-1/events", headers,
                        [&](const httplib::Response& res) {
                          content_type = res.get_header_value("Content-Type");
                          return true;
                        },
                        [&](const char* data, std::size_t n) {
                          text.append(data, n);
                          return true;
                        });
  ASSERT_TRUE(r) << "the stream did not end";
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(content_type, "text/event-stream");
  const auto frames = parse_sse(text);
  ASSERT_EQ(frames.size(), 4u) << text;
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(frames[i].id, i + 1);
  EXPECT_EQ(frames[0].event, "progress");
  EXPECT_EQ(frames[3].event, "done");
  EXPECT_EQ(frames[3].data["id"], "job-1");
}

TEST_F(HttpApiTest, LastEventIdResumes) {
  start();
  backend_.add_job("job-1");
  for (const char* type : {"progress", "progress", "progress", "done"}) backend_.push_event("job-1", type);
  std::string text;
  auto r = client().Get("/v1/renders/job-1/events", {{"Last-Event-ID", "2"}}, [&](const char* d, std::size_t n) {
    text.append(d, n);
    return true;
  });
  ASSERT_TRUE(r);
  const auto frames = parse_sse(text);
  ASSERT_EQ(frames.size(), 2u) << text;
  EXPECT_EQ(frames[0].id, 3u);
  EXPECT_EQ(frames[1].id, 4u);

  // Resuming after the terminal event of a finished job ends at once.
  backend_.set_state("job-1", "done");
  std::string rest;
  const auto t0 = std::chrono::steady_clock::now();
  auto after_end = client().Get("/v1/renders/job-1/events", {{"Last-Event-ID", "4"}}, [&](const char* d, std::size_t n) {
    rest.append(d, n);
    return true;
  });
  ASSERT_TRUE(after_end);
  EXPECT_TRUE(parse_sse(rest).empty());
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);

  auto bad = client().Get("/v1/renders/job-1/events", {{"Last-Event-ID", "abc"}});
  expect_problem(bad, 400);
  EXPECT_EQ(first_field(bad), "Last-Event-ID");
}

TEST_F(HttpApiTest, LiveEventsWithKeepalivesUntilDone) {
  start();
  backend_.add_job("job-1");
  std::thread producer([this] {
    std::this_thread::sleep_for(300ms);  // idle long enough for keep-alive comments
    backend_.push_event("job-1", "progress");
    std::this_thread::sleep_for(50ms);
    backend_.push_event("job-1", "done");
  });
  std::string text;
  auto r = client().Get("/v1/renders/job-1/events", [&](const char* d, std::size_t n) {
    text.append(d, n);
    return true;
  });
  producer.join();
  ASSERT_TRUE(r);
  EXPECT_NE(text.find(": keepalive\n\n"), std::string::npos) << text;
  const auto frames = parse_sse(text);
  ASSERT_EQ(frames.size(), 2u) << text;
  EXPECT_EQ(frames[1].event, "done");
  EXPECT_TRUE(streams_drain(1s));
}

TEST_F(HttpApiTest, AbruptStreamClientsFreeTheirSlot) {
  start();
  backend_.add_job("job-1");
  backend_.push_event("job-1", "progress");
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port_));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request = "GET /v1/renders/job-1/events HTTP/1.1\r\nHost: t\r\n\r\n";
  ASSERT_EQ(::send(fd, request.data(), request.size(), MSG_NOSIGNAL), static_cast<ssize_t>(request.size()));
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string got;
  char buf[1024];
  while (got.find("id: 1") == std::string::npos) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    ASSERT_GT(n, 0);
    got.append(buf, static_cast<std::size_t>(n));
  }
  EXPECT_EQ(api_->open_streams(), 1);
  linger hard{1, 0};  // close with a reset, like a crashed client
  ::setsockopt(fd, SOL_SOCKET, SO_LINGER, &hard, sizeof hard);
  ::close(fd);
  EXPECT_TRUE(streams_drain(3s)) << "the server did not notice the peer left";
  expect_healthy();
}

TEST_F(HttpApiTest, StreamsBeyondTheCapAre503) {
  HttpOptions o = test_options();
  o.max_concurrent_streams = 1;
  start(o);
  backend_.add_job("job-1");
  std::atomic<bool> opened{false};
  std::thread first([&] {
    client().Get("/v1/renders/job-1/events", [&](const char*, std::size_t) {
      opened = true;
      return true;
    });
  });
  for (int i = 0; i < 300 && !opened; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(opened);
  auto second = client().Get("/v1/renders/job-1/events");
  expect_problem(second, 503);
  EXPECT_EQ(second->get_header_value("Retry-After"), "5");
  expect_healthy();
  backend_.push_event("job-1", "done");
  first.join();
  EXPECT_TRUE(streams_drain(1s));
  backend_.add_job("job-2");
  backend_.push_event("job-2", "done");
  auto third = client().Get("/v1/renders/job-2/events");
  ASSERT_TRUE(third);
  EXPECT_EQ(third->status, 200);
}

TEST_F(HttpApiTest, StoppingTheServerEndsOpenStreams) {
  start();
  backend_.add_job("job-1");
  std::atomic<bool> opened{false};
  std::thread reader([&] {
    client().Get("/v1/renders/job-1/events", [&](const char*, std::size_t) {
      opened = true;
      return true;
    });
  });
  for (int i = 0; i < 300 && !opened; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(opened);
  const auto t0 = std::chrono::steady_clock::now();
  server_->stop();
  thread_.join();
  reader.join();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  EXPECT_EQ(api_->open_streams(), 0);
}

// --- Metrics, token, OpenAPI ----------------------------------------------------

TEST_F(HttpApiTest, MetricsAreValidPrometheusText) {
  start();
  expect_problem(client().Get("/v1/renders/none"), 404);
  // A response is counted once it has been sent (cpp-httplib's logger runs
  // after the write), which may be just after the client has read it.
  auto r = client().Get("/metrics");
  for (int i = 0; i < 200 && r && r->body.find("code=\"404\"") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    r = client().Get("/metrics");
  }
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "text/plain; version=0.0.4; charset=utf-8");
  const std::regex sample(R"(([a-zA-Z_:][a-zA-Z0-9_:]*)(\{[a-zA-Z_][a-zA-Z0-9_]*="[^"\\]*"(,[a-zA-Z_][a-zA-Z0-9_]*="[^"\\]*")*\})? (-?[0-9.]+(e[-+]?[0-9]+)?|NaN|[-+]Inf))");
  const std::regex comment(R"(# (HELP|TYPE) ([a-zA-Z_:][a-zA-Z0-9_:]*) .+)");
  std::set<std::string> typed;
  std::istringstream lines(r->body);
  int samples = 0;
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_match(line, m, comment)) {
      if (m[1] == "TYPE") typed.insert(m[2]);
      if (m[1] == "TYPE" && line.ends_with(" histogram"))  // its samples: _bucket, _sum, _count
        for (const char* suffix : {"_bucket", "_sum", "_count"}) typed.insert(m[2].str() + suffix);
      continue;
    }
    ASSERT_TRUE(std::regex_match(line, m, sample)) << line;
    EXPECT_TRUE(typed.count(m[1])) << "no # TYPE before " << line;
    EXPECT_TRUE(m[1].str().starts_with("skyfarm_")) << line;
    ++samples;
  }
  EXPECT_GE(samples, 10);
  for (const char* expected : {"skyfarm_queue_units 12\n", "skyfarm_units_in_flight 3\n", "skyfarm_workers 2\n",
                               "skyfarm_samples_per_second 1500000\n", "skyfarm_unit_failures_total 1\n",
                               "skyfarm_jobs{state=\"running\"} 2\n",
                               "skyfarm_http_requests_total{code=\"404\",method=\"GET\",route=\"/v1/renders/{id}\"} 1\n",
                               "# TYPE skyfarm_unit_failures_total counter\n", "skyfarm_results_refused_total 2\n",
                               "# TYPE skyfarm_results_refused_total counter\n", "skyfarm_disk_used_bytes 123456789\n",
                               "skyfarm_disk_budget_bytes 1000000000\n"})
    EXPECT_NE(r->body.find(expected), std::string::npos) << expected << " in\n" << r->body;
}

TEST_F(HttpApiTest, BearerTokenGuardsEverythingButHealthz) {
  HttpOptions o = test_options();
  o.token = "s3cret-token";
  start(o);
  auto c = client();
  auto none = c.Get("/v1/renders");
  expect_problem(none, 401);
  EXPECT_TRUE(none->get_header_value("WWW-Authenticate").starts_with("Bearer"));
  auto wrong = c.Get("/v1/renders", {{"Authorization", "Bearer s3cret-tokeX"}});
  expect_problem(wrong, 401);
  EXPECT_NE(wrong->get_header_value("WWW-Authenticate").find("invalid_token"), std::string::npos);
  expect_problem(c.Get("/v1/renders", {{"Authorization", "Basic czNjcmV0LXRva2Vu"}}), 401);
  expect_problem(c.Get("/metrics"), 401);
  expect_problem(c.Get("/v1/openapi.yaml"), 401);
  expect_problem(post(good_request()), 401);
  EXPECT_TRUE(backend_.submissions().empty());

  auto ok = c.Get("/v1/renders", {{"Authorization", "Bearer s3cret-token"}});
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  auto lower = c.Get("/metrics", {{"Authorization", "bearer s3cret-token"}});
  ASSERT_TRUE(lower);
  EXPECT_EQ(lower->status, 200);
  auto submitted = post(good_request(), {{"Authorization", "Bearer s3cret-token"}});
  ASSERT_TRUE(submitted);
  EXPECT_EQ(submitted->status, 202);
  expect_healthy();

  // Final images of an authenticated API are not for shared caches.
  backend_.add_job("job-9");
  backend_.set_image("job-9", ImageFormat::kPng, {temp_file("final.png", "P"), "\"h\"", true});
  auto png = c.Get("/v1/renders/job-9/image.png", {{"Authorization", "Bearer s3cret-token"}});
  ASSERT_TRUE(png);
  EXPECT_EQ(png->get_header_value("Cache-Control"), "private, max-age=31536000, immutable");
}

TEST_F(HttpApiTest, OpenApiDocumentIsServedAndNamesEveryRoute) {
  start();
  auto r = client().Get("/v1/openapi.yaml");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/yaml");
  EXPECT_EQ(r->body, read_text(fs::path(SKYFARM_SOURCE_DIR) / "api" / "openapi.yaml"));
  EXPECT_TRUE(r->body.starts_with("openapi: 3.0"));
  for (const char* route : {"/v1/renders:", "/v1/renders/{id}:", "/v1/renders/{id}/image.exr:",
                            "/v1/renders/{id}/image.png:", "/v1/renders/{id}/events:", "/v1/workers:",
                            "/v1/openapi.yaml:", "/healthz:", "/metrics:", "application/problem+json",
                            "Idempotency-Key", "Last-Event-ID", "If-None-Match"})
    EXPECT_NE(r->body.find(route), std::string::npos) << route;
}

TEST_F(HttpApiTest, StaysHealthyAfterManyBadRequests) {
  start();
  auto c = client();
  for (int i = 0; i < 120; ++i) {
    switch (i % 4) {
      case 0: expect_problem(post("{\"camera\": " + std::to_string(i)), 400); break;
      case 1: expect_problem(c.Get("/v1/renders/" + std::string(65 + i, 'x')), 400); break;
      case 2: expect_problem(post("[]", {}, "text/csv"), 415); break;
      default: expect_problem(c.Get("/v1/renders?limit=-" + std::to_string(i)), 400); break;
    }
  }
  expect_healthy();
  auto metrics = c.Get("/metrics");
  ASSERT_TRUE(metrics);
  // 30 bad requests on each of three routes, labelled by template (never by the raw path).
  for (const char* series : {"{code=\"400\",method=\"POST\",route=\"/v1/renders\"} 30\n",
                             "{code=\"400\",method=\"GET\",route=\"/v1/renders/{id}\"} 30\n",
                             "{code=\"400\",method=\"GET\",route=\"/v1/renders\"} 30\n"})
    EXPECT_NE(metrics->body.find(std::string("skyfarm_http_requests_total") + series), std::string::npos)
        << series << metrics->body;
}

// --- Pure checks ---------------------------------------------------------------------

TEST(HttpChecks, JobIds) {
  EXPECT_TRUE(valid_job_id("a"));
  EXPECT_TRUE(valid_job_id("job_1-A"));
  EXPECT_TRUE(valid_job_id(std::string(64, 'x')));
  EXPECT_FALSE(valid_job_id(""));
  EXPECT_FALSE(valid_job_id(std::string(65, 'x')));
  for (const char* bad : {"..", "a/b", "a.b", "a b", "a%2F", "\xc3\xa9"}) EXPECT_FALSE(valid_job_id(bad)) << bad;
}

TEST(HttpChecks, IdempotencyKeys) {
  EXPECT_TRUE(valid_idempotency_key("8e03978e-40d5-43e8-bc93-6894a57f9324"));
  EXPECT_TRUE(valid_idempotency_key("\"quoted\""));
  EXPECT_TRUE(valid_idempotency_key(std::string(255, '!')));
  EXPECT_FALSE(valid_idempotency_key(""));
  EXPECT_FALSE(valid_idempotency_key(std::string(256, 'a')));
  EXPECT_FALSE(valid_idempotency_key("a b"));
  EXPECT_FALSE(valid_idempotency_key("tab\t"));
  EXPECT_FALSE(valid_idempotency_key("\x7f"));
}

TEST(HttpChecks, MediaTypes) {
  EXPECT_EQ(check_json_media_type("application/json"), MediaTypeCheck::kOk);
  EXPECT_EQ(check_json_media_type(" APPLICATION/JSON ; Charset=UTF-8"), MediaTypeCheck::kOk);
  EXPECT_EQ(check_json_media_type("application/json; boundary=x"), MediaTypeCheck::kOk);
  EXPECT_EQ(check_json_media_type(""), MediaTypeCheck::kMissing);
  EXPECT_EQ(check_json_media_type("application/jsonx"), MediaTypeCheck::kNotJson);
  EXPECT_EQ(check_json_media_type("text/json"), MediaTypeCheck::kNotJson);
  EXPECT_EQ(check_json_media_type("application/json; charset=utf-16"), MediaTypeCheck::kBadCharset);
}

TEST(HttpChecks, Decimals) {
  EXPECT_EQ(parse_decimal("0", 10), 0u);
  EXPECT_EQ(parse_decimal("10", 10), 10u);
  EXPECT_EQ(parse_decimal("18446744073709551615", UINT64_MAX), UINT64_MAX);
  for (const char* bad : {"", "11", "-1", "+1", "1e1", " 1", "1.0", "18446744073709551616"})
    EXPECT_FALSE(parse_decimal(bad, bad[0] == '1' && std::string(bad).size() > 10 ? UINT64_MAX : 10)) << bad;
  EXPECT_FALSE(parse_decimal("9", 5));
}

TEST(HttpChecks, JsonDepth) {
  EXPECT_FALSE(json_deeper_than("{}", 1));
  EXPECT_TRUE(json_deeper_than("{\"a\": []}", 1));
  EXPECT_FALSE(json_deeper_than("{\"a\": \"[[[[\\\"[[[\"}", 1));
  EXPECT_FALSE(json_deeper_than(std::string(32, '[') + std::string(32, ']'), 32));
  EXPECT_TRUE(json_deeper_than(std::string(33, '['), 32));
}

TEST(HttpChecks, BearerTokensAndConstantTimeCompare) {
  EXPECT_EQ(bearer_token("Bearer abc"), "abc");
  EXPECT_EQ(bearer_token("bearer   abc "), "abc");
  EXPECT_FALSE(bearer_token("Basic abc"));
  EXPECT_FALSE(bearer_token("Bearer"));
  EXPECT_FALSE(bearer_token("Bearer "));
  EXPECT_TRUE(constant_time_equal("secret", "secret"));
  EXPECT_FALSE(constant_time_equal("secreT", "secret"));
  EXPECT_FALSE(constant_time_equal("secret-longer", "secret"));
  EXPECT_FALSE(constant_time_equal("sec", "secret"));
  EXPECT_FALSE(constant_time_equal("", "secret"));
}

TEST(HttpChecks, IfNoneMatch) {
  EXPECT_TRUE(if_none_match_matches("\"a\"", "\"a\""));
  EXPECT_TRUE(if_none_match_matches("\"b\", W/\"a\"", "\"a\""));
  EXPECT_TRUE(if_none_match_matches("*", "\"a\""));
  EXPECT_FALSE(if_none_match_matches("\"b\"", "\"a\""));
  EXPECT_FALSE(if_none_match_matches("", "\"a\""));
}

TEST(HttpMetrics, UnknownNumbersBecomeGaugesAndOthersAreSkipped) {
  ResponseCounter counter;
  counter.count(200);
  counter.count(200);
  counter.count(999);  // out of range: ignored
  const std::string text = prometheus_text(
      {{"queue_units", 1}, {"odd key!", 2.5}, {"label", "text"}, {"nan", std::nan("")}}, counter, 3);
  EXPECT_NE(text.find("skyfarm_odd_key_ 2.5\n"), std::string::npos) << text;
  EXPECT_NE(text.find("skyfarm_nan NaN\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("label"), std::string::npos) << text;
  EXPECT_NE(text.find("skyfarm_http_requests_total{code=\"200\"} 2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("skyfarm_http_event_streams 3\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace skyfarm::server

// The connection gate (server/http/http_gate.h) in front of the HTTP API, on
// loopback with small deadlines: slow request heads and bodies are cut with
// 408 at their deadline (in the gate and on a pool thread, and on a
// keep-alive connection's next request), slow clients hold no thread (200 of
// them and the API still answers), the connection cap refuses the one
// beyond with 503, event streams outlive the deadlines, and fast clients
// keep their keep-alive and pipelined requests.
#include "server/http/http_gate.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "tests/server/http/fake_backend.h"
#include "tests/support/http_fixture.h"
#include "tests/support/test_files.h"

namespace skyfarm::server {
namespace {

using namespace std::chrono_literals;

constexpr auto kByteInterval = 500ms;  // a slow client's pace
// Bytes a slow client sends before the test gives up on being cut: at
// kByteInterval, well past the 1 s deadlines below, and fewer than any head.
constexpr std::size_t kSlowBytesMax = 8;

int connect_loopback(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::send(fd, text.data(), text.size(), MSG_NOSIGNAL);
    if (n <= 0) return false;
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

// Takes what has arrived without waiting; false once the server closed.
bool drain(int fd, std::string& got) {
  char buf[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n > 0) {
      got.append(buf, static_cast<std::size_t>(n));
      continue;
    }
    return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
  }
}

struct Trickle {
  bool closed = false;     // the server closed the connection
  std::size_t sent = 0;    // bytes sent before that
  std::string received;
};

// Sends `text` one byte per kByteInterval (at most kSlowBytesMax bytes)
// until the server closes the connection.
Trickle trickle(int fd, std::string_view text) {
  Trickle t;
  while (t.sent < std::min(text.size(), kSlowBytesMax)) {
    if (!drain(fd, t.received) || ::send(fd, text.data() + t.sent, 1, MSG_NOSIGNAL) != 1) {
      t.closed = true;
      return t;
    }
    ++t.sent;
    std::this_thread::sleep_for(kByteInterval);
  }
  t.closed = !drain(fd, t.received);
  return t;
}

// Everything until the server closes, waiting at most 3 s for each piece.
std::string read_to_close(int fd) {
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string got;
  char buf[4096];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  return got;
}

// What arrives until `done` says so, the server closes, or 3 s pass without a byte.
template <class Done>
std::string read_until(int fd, Done done) {
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string got;
  char buf[4096];
  while (!done(got)) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    got.append(buf, static_cast<std::size_t>(n));
  }
  return got;
}

// One response with a Content-Length body.
std::string read_response(int fd) {
  return read_until(fd, [](const std::string& got) {
    const std::size_t end = got.find("\r\n\r\n");
    if (end == std::string::npos) return false;
    const std::size_t at = got.find("Content-Length: ");
    return at != std::string::npos && at < end && got.size() >= end + 4 + std::stoul(got.substr(at + 16));
  });
}

int count_of(const std::string& text, std::string_view what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

HttpOptions api_options() {
  HttpOptions o;
  o.sse_keepalive = 100ms;
  o.max_concurrent_streams = 4;
  return o;
}

class HttpGateTest : public testing::HttpFixture {
 protected:
  void start(std::chrono::milliseconds header_timeout, std::chrono::milliseconds body_timeout) {
    gate_.header_timeout = header_timeout;
    gate_.body_timeout = body_timeout;
    serve(api_options());
  }
  std::string metrics() {
    auto r = client().Get("/metrics");
    return r ? r->body : "";
  }
};

const std::string kHealthz = "GET /healthz HTTP/1.1\r\nHost: t\r\n\r\n";

// Sends a POST head ending with `body_header` (its body framing and the
// head's end, e.g. "Content-Length: 100\r\n\r\n"), then trickles a 100-byte
// body; asserts the connection was cut with a 408 before the body was sent.
void expect_slow_body_cut(int port, const std::string& body_header) {
  const int fd = connect_loopback(port);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(send_all(fd, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n" +
                               body_header));
  const Trickle t = trickle(fd, std::string(100, ' '));
  ::close(fd);
  EXPECT_TRUE(t.closed) << "still open after " << t.sent << " body bytes";
  EXPECT_LT(t.sent, kSlowBytesMax);
  EXPECT_TRUE(t.received.starts_with("HTTP/1.1 408 ")) << t.received;
}

TEST_F(HttpGateTest, SlowHeadIsCutAtTheHeaderDeadline) {
  start(1s, 30s);
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  const Trickle t = trickle(fd, kHealthz);
  ::close(fd);
  EXPECT_TRUE(t.closed) << "still open after " << t.sent << " bytes";
  EXPECT_LT(t.sent, kSlowBytesMax);
  EXPECT_TRUE(t.received.starts_with("HTTP/1.1 408 ")) << t.received;
  EXPECT_NE(t.received.find("application/problem+json"), std::string::npos);
  EXPECT_NE(metrics().find("skyfarm_http_request_timeouts_total{part=\"head\"} 1\n"), std::string::npos);
}

// A Content-Length body small enough to wait in the gate.
TEST_F(HttpGateTest, SlowBodyIsCutAtTheBodyDeadline) {
  start(30s, 1s);
  expect_slow_body_cut(port_, "Content-Length: 100\r\n\r\n");
}

// A chunked body waits in the gate too.
TEST_F(HttpGateTest, SlowChunkedBodyIsCutAtTheBodyDeadline) {
  start(30s, 1s);
  expect_slow_body_cut(port_, "Transfer-Encoding: chunked\r\n\r\n64\r\n");
  // The thread went back to the pool.
  auto r = client().Get("/healthz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

// A body larger than the gate holds is read on a pool thread, under the
// same deadline, and the thread is free again after it.
TEST_F(HttpGateTest, SlowLargeBodyIsCutOnThePoolThread) {
  gate_.max_buffered_body = 16;
  start(30s, 1s);
  expect_slow_body_cut(port_, "Content-Length: 100\r\n\r\n");
  for (int i = 0; i < 300 && server_->open_connections() > 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(server_->open_connections(), 0);
  EXPECT_NE(metrics().find("skyfarm_http_request_timeouts_total{part=\"body\"} 1\n"), std::string::npos);
}

// A head that never ends is refused once it outgrows what any request needs.
TEST_F(HttpGateTest, EndlessHeadIsRefusedWith431) {
  start(30s, 30s);
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  std::string head = "GET /healthz HTTP/1.1\r\n";
  for (int i = 0; head.size() < 80 * 1024; ++i) head += "X-Filler-" + std::to_string(i) + ": " + std::string(100, 'x') + "\r\n";
  send_all(fd, head);  // may fail part-way once the server has closed
  const std::string answer = read_to_close(fd);
  ::close(fd);
  EXPECT_TRUE(answer.starts_with("HTTP/1.1 431 ")) << answer.substr(0, 200);
}

// On a keep-alive connection the next head is due within the deadline
// counted from the end of the previous response.
TEST_F(HttpGateTest, KeepAliveConnectionWithASlowNextHeadIsCut) {
  start(1s, 30s);
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(send_all(fd, kHealthz));
  const std::string first = read_response(fd);
  ASSERT_TRUE(first.starts_with("HTTP/1.1 200 ")) << first;
  const Trickle t = trickle(fd, kHealthz);
  ::close(fd);
  EXPECT_TRUE(t.closed);
  EXPECT_LT(t.sent, kSlowBytesMax);
  EXPECT_TRUE(t.received.starts_with("HTTP/1.1 408 ")) << t.received;
}

TEST_F(HttpGateTest, TwoHundredSlowClientsDoNotStallTheApi) {
  start(30s, 30s);
  backend_.add_job("job-1");
  std::vector<int> slow;
  for (int i = 0; i < 200; ++i) {
    const int fd = connect_loopback(port_);
    ASSERT_GE(fd, 0);
    slow.push_back(fd);
    // Half a head, and half a body: both wait for more.
    ASSERT_TRUE(send_all(fd, i % 2 ? "GET /healthz HTTP/1.1\r\nHo"
                                   : "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Length: 50\r\n\r\n{"));
  }
  // Answered within 2 s (the client's limits), not after the slow ones time out.
  httplib::Client c("127.0.0.1", port_);
  c.set_connection_timeout(2);
  c.set_read_timeout(2);
  auto health = c.Get("/healthz");
  ASSERT_TRUE(health) << httplib::to_string(health.error());
  EXPECT_EQ(health->status, 200);
  auto list = c.Get("/v1/renders");
  ASSERT_TRUE(list) << httplib::to_string(list.error());
  EXPECT_EQ(list->status, 200);
  EXPECT_NE(list->body.find("job-1"), std::string::npos);
  EXPECT_GE(server_->open_connections(), 200);
  for (int fd : slow) ::close(fd);
}

TEST_F(HttpGateTest, ConnectionCapRefusesTheOneBeyond) {
  gate_.max_connections = 4;
  start(30s, 30s);
  std::vector<int> held;
  for (int i = 0; i < 4; ++i) {
    const int fd = connect_loopback(port_);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(send_all(fd, "GET"));
    held.push_back(fd);
  }
  const int beyond = connect_loopback(port_);
  ASSERT_GE(beyond, 0);
  const std::string refused = read_to_close(beyond);
  ::close(beyond);
  EXPECT_TRUE(refused.starts_with("HTTP/1.1 503 ")) << refused;
  EXPECT_NE(refused.find("Retry-After: 1\r\n"), std::string::npos);
  EXPECT_EQ(server_->stats().refused, 1u);
  // One leaves: a new client gets in.
  ::close(held.back());
  held.pop_back();
  for (int i = 0; i < 300 && server_->open_connections() > 3; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(server_->open_connections(), 3);
  const int next = connect_loopback(port_);
  ASSERT_GE(next, 0);
  ASSERT_TRUE(send_all(next, kHealthz));
  const std::string answer = read_response(next);
  EXPECT_TRUE(answer.starts_with("HTTP/1.1 200 ")) << answer;
  ::close(next);
  for (int fd : held) ::close(fd);
}

// The deadlines bound what the client sends, never a response: an event
// stream lasting longer than both is not cut.
TEST_F(HttpGateTest, EventStreamsOutliveTheDeadlines) {
  start(500ms, 500ms);
  backend_.add_job("job-1");
  std::thread producer([this] {
    std::this_thread::sleep_for(1200ms);
    backend_.push_event("job-1", "progress");
    std::this_thread::sleep_for(600ms);
    backend_.push_event("job-1", "done");
  });
  std::string text;
  auto r = client().Get("/v1/renders/job-1/events", [&](const char* d, std::size_t n) {
    text.append(d, n);
    return true;
  });
  producer.join();
  ASSERT_TRUE(r) << httplib::to_string(r.error());
  EXPECT_EQ(r->status, 200);
  EXPECT_NE(text.find("event: progress"), std::string::npos) << text;
  EXPECT_NE(text.find("event: done"), std::string::npos) << text;
}

TEST_F(HttpGateTest, FastClientsKeepTheirConnection) {
  start(2s, 2s);
  // Sequential requests on one connection, spaced less than the deadlines apart.
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(send_all(fd, kHealthz));
    const std::string answer = read_response(fd);
    EXPECT_TRUE(answer.starts_with("HTTP/1.1 200 ")) << i << ": " << answer;
    std::this_thread::sleep_for(300ms);
  }
  // Pipelined: three requests in one write, three answers in order.
  ASSERT_TRUE(send_all(fd, kHealthz + "GET /v1/renders HTTP/1.1\r\nHost: t\r\n\r\n" + kHealthz));
  const std::string answers = read_until(fd, [](const std::string& got) {
    return count_of(got, "HTTP/1.1 200 ") == 3 && got.ends_with("{\"status\":\"ok\"}");
  });
  EXPECT_EQ(count_of(answers, "HTTP/1.1 200 "), 3) << answers;
  EXPECT_NE(answers.find("\"renders\""), std::string::npos) << answers;
  ::close(fd);
  // httplib's client reuses its connection too.
  httplib::Client c("127.0.0.1", port_);
  c.set_keep_alive(true);
  c.set_read_timeout(3);
  for (int i = 0; i < 3; ++i) {
    auto r = c.Get("/healthz");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
  }
  for (int i = 0; i < 300 && server_->open_connections() > 1; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(server_->open_connections(), 1);
}

// A chunked body that arrives in pieces (chunks split, an extension) is
// served whole once its last chunk is in.
TEST_F(HttpGateTest, ChunkedBodiesArrivingInPiecesAreServed) {
  start(5s, 5s);
  const std::string body = skyfarm::testing::read_text(skyfarm::testing::kExamples / "noon_fisheye.json");
  std::ostringstream wire;
  wire << std::hex << 10 << ";ext=1\r\n" << body.substr(0, 10) << "\r\n" << body.size() - 10 << "\r\n"
       << body.substr(10) << "\r\n0\r\n\r\n";
  const std::string chunks = wire.str();
  const int fd = connect_loopback(port_);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(send_all(fd, "POST /v1/renders HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\n"
                           "Transfer-Encoding: chunked\r\n\r\n"));
  for (std::size_t at = 0; at < chunks.size(); at += 7) {
    ASSERT_TRUE(send_all(fd, std::string_view(chunks).substr(at, 7)));
    if (at % 70 == 0) std::this_thread::sleep_for(20ms);
  }
  const std::string answer = read_response(fd);
  ::close(fd);
  EXPECT_TRUE(answer.starts_with("HTTP/1.1 202 ")) << answer;
  EXPECT_EQ(backend_.submissions().size(), 1u);
}

}  // namespace
}  // namespace skyfarm::server

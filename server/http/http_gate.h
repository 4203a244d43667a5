// GatedHttpServer: an httplib::Server whose connections wait for their whole
// request head (and a small body) in one epoll thread before a pool thread
// serves them, under deadlines and a connection cap.
//
// Why: cpp-httplib 0.11 serves a connection on one pool thread from accept to
// close and bounds only each single read, so a client sending one header byte
// every few seconds, or trickling a body, holds a thread indefinitely; a few
// dozen such clients stall the whole API.  Here a connection holds no thread
// while its request arrives:
//   accept (httplib's own loop) -> the gate (epoll, no thread per connection)
//     until the head ends ("\r\n\r\n") and, for a body (Content-Length or
//     chunked) within max_buffered_body, until the body is in too
//   -> a pool thread runs httplib's request processing on the bytes read, and
//     reads any rest of the body (larger, or after "Expect: 100-continue")
//     under the body deadline
//   -> after the response, a keep-alive connection goes back to the gate.
// Responses (event streams, long probe waits) are not bounded here: the
// deadlines cover only what the client sends.
//
// Parameters (GateOptions):
//   header_timeout     the whole request head must arrive within this, counted
//                      from the connection's first byte, or from the end of
//                      the previous response on a keep-alive connection;
//                      then 408 and the connection is closed
//   body_timeout       the whole body must arrive within this after the head;
//                      then 408 (when no response has started) and closed
//   max_connections    connections open at once (waiting or being served);
//                      one beyond is answered 503 at once and closed
//   max_buffered_body  bodies up to this size wait in the gate (no thread);
//                      larger ones are read on a pool thread
//   buffer_budget      bytes the gate may hold for all waiting bodies; beyond,
//                      bodies are read on a pool thread
// A connection silent before its first byte is closed after httplib's
// keep-alive timeout (set_keep_alive_timeout), as httplib does; requests per
// connection follow set_keep_alive_max_count, per-read and per-write waits
// set_read_timeout / set_write_timeout.  The pool is the one new_task_queue
// makes (as set before listening).
//
// Use it as an httplib::Server: bind, then listen_after_bind() (or listen())
// on this type; stop() from any thread.
#pragma once
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace skyfarm::server {

struct GateOptions {
  std::chrono::milliseconds header_timeout = std::chrono::seconds(10);
  std::chrono::milliseconds body_timeout = std::chrono::seconds(30);
  int max_connections = 1024;
  std::size_t max_buffered_body = 1 << 20;
  std::size_t buffer_budget = std::size_t{64} << 20;
};

// What /metrics shows of the gate.
struct GateStats {
  int open = 0;                    // connections open now
  std::uint64_t refused = 0;       // beyond max_connections (503)
  std::uint64_t head_timeouts = 0; // 408 for a late head
  std::uint64_t body_timeouts = 0; // 408 for a late body
};

// Appends the gate's Prometheus metrics: skyfarm_http_connections_open,
// skyfarm_http_connections_refused_total, skyfarm_http_request_timeouts_total{part}.
void append_gate_metrics(std::string& out, const GateStats& stats);

class ConnectionGate;

class GatedHttpServer : public httplib::Server {
 public:
  explicit GatedHttpServer(GateOptions options = {});
  ~GatedHttpServer() override;

  // These hide httplib::Server's: they put the gate in front of the pool.
  bool listen_after_bind();
  bool listen(const std::string& host, int port, int socket_flags = 0);

  // Connections open now (waiting in the gate or being served).
  int open_connections() const;
  GateStats stats() const;

 private:
  friend class ConnectionGate;
  friend class GateQueue;
  // httplib's accept loop hands every accepted socket here (a virtual it
  // declares for its TLS server); the gate takes it over.
  bool process_and_close_socket(socket_t sock) override;
  // One request of a connection the gate found ready, on a pool thread.
  bool serve_one(httplib::Stream& stream, bool close_connection, bool& connection_closed);
  bool stopping() const { return svr_sock_ == INVALID_SOCKET; }
  std::size_t keep_alive_max_count() const { return keep_alive_max_count_; }
  std::chrono::seconds keep_alive_timeout() const { return std::chrono::seconds(keep_alive_timeout_sec_); }
  std::chrono::microseconds read_timeout() const;
  std::chrono::microseconds write_timeout() const;

  const GateOptions options_;
  std::function<httplib::TaskQueue*()> pool_factory_;
  std::atomic<ConnectionGate*> gate_{nullptr};
  std::atomic<int> open_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> head_timeouts_{0};
  std::atomic<std::uint64_t> body_timeouts_{0};
};

}  // namespace skyfarm::server

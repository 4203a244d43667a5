// The farm's ZeroMQ broker: one thread owning one ROUTER socket, between the
// workers (DEALERs, api/wire.h protocol) and a BrokerBackend (the JobService,
// or a fake in tests).  No other thread touches the socket; other threads
// talk to the broker only through stop(), wake() and stats().
//
// Per worker (keyed by its ROUTER routing identity; its READY "id" is the
// name the backend sees):
//   security    with curve_secret_key set the ROUTER is a CURVE server: every
//               connection is authenticated by a ZAP handler (an inproc REP
//               socket served on the broker thread) applying WorkerAuth
//               (server/broker/worker_auth.h) to the client's public key, and all
//               traffic is encrypted.  Denials, and handshakes that fail
//               because the client speaks another mechanism (NULL, PLAIN; seen
//               through a socket monitor), count as auth_failures.  Without a
//               key the NULL mechanism lets anyone in: for tests of the
//               protocol only (skyfarm-server always sets one).
//   handshake   READY (right version; its token is ignored) ->
//               backend.worker_joined(id, header without the token) and an
//               immediate HEARTBEAT; a wrong version gets a fatal
//               DISCONNECT.  A READY whose id is registered under another
//               identity is refused ("worker id in use", fatal) while that
//               one is alive; once it has missed a heartbeat (silent for two
//               of its intervals) the new READY ends it (worker_left) and takes
//               its place: a worker that reconnected.  Any other message from
//               an unknown peer is answered with REREGISTER.
//   credit      the worker holds at most `slots` (its READY) units; a UNIT is
//               sent only while it has a free slot (backend.next_unit), one
//               unit per worker per round-robin round.  RESULT, FAILED and
//               CANCEL free a slot; a draining worker (HEARTBEAT
//               "draining") gets no more units.  A worker that announces
//               "prefetch" (api/wire.h) gets more credit when its units are
//               short: enough for pipeline_target of work at the render time
//               its RESULTs report (a moving average, over its cores), at most
//               slots + prefetch, so tiny units do not idle it for a round
//               trip after each.  Dispatch runs when credit came free, a
//               worker joined or left, on wake(), after the timeout check,
//               and otherwise every poll_interval.
//   liveness    every message from the worker counts as a heartbeat; the
//               broker heartbeats every worker each heartbeat_interval; a
//               worker silent for heartbeat_liveness x max(own interval,
//               worker's heartbeat_ms) is lost -> backend.worker_left (not
//               while the broker is behind on its input: that worker's
//               messages may be waiting in the socket).  So
//               are DISCONNECT and a send that fails (EHOSTUNREACH under
//               ROUTER_MANDATORY, or EAGAIN at the high-water mark: sends
//               never block).
//   results     RESULT -> backend.unit_done, FAILED -> backend.unit_failed,
//               only for an attempt this broker sent to that worker (its
//               in-flight set) with the same job, tile, batch and pass:
//               anything else is refused (results_refused, logged) and never
//               reaches the backend, and an attempt held by another worker
//               stays with it.  The late answer of an attempt cancelled here
//               is dropped silently.  The film-tile bytes are not decoded here.
//   cancels     backend.take_cancelled_attempts() each tick -> CANCEL to the
//               holders still connected (their slot is freed at once).
//   timeouts    backend.check_timeouts(now) every timeout_check_interval.
//   assets      ASSET_GET from a registered worker is answered with ASSET:
//               the mesh file `asset_file` returns (ok), or ok=false and a
//               sentence when it returns nothing (not in the store, or no
//               store).  The file is read on the broker thread: tens of ms
//               for tens of MB, a pause the heartbeats' liveness (seconds)
//               absorbs, once per worker and asset (workers cache them).
//               A send that fails loses the worker, as for a UNIT.
// Malformed or unexpected messages are counted (stats) and dropped; an
// exception from the backend is logged and counted, never kills the thread.
//
// stop(): DISCONNECT to every worker, worker_left for each, close with a
// short bounded linger (so the DISCONNECTs can leave; shutdown_linger), join,
// terminate the context.  It never hangs on a dead peer.  A Broker may be
// started again after stop() (a new socket and context).
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "server/broker/broker_backend.h"
#include "server/broker/worker_auth.h"

namespace skyfarm::server {

struct BrokerOptions {
  // ZeroMQ endpoint to bind; "tcp://127.0.0.1:*" picks a free port (see bound_endpoint()).
  std::string endpoint = "tcp://127.0.0.1:5555";
  std::chrono::milliseconds heartbeat_interval{1000};
  int heartbeat_liveness = 3;  // missed intervals before a worker is declared lost
  // The server's CURVE secret key (Z85); empty: the NULL mechanism (no
  // authentication, no encryption: tests only).
  std::string curve_secret_key;
  // Which worker keys the ZAP handler lets in (used with curve_secret_key).
  WorkerAuthOptions auth;
  // Longest wait in zmq_poll: the latency of stop(), of noticing cancels and
  // of dispatching work that appears without wake() (capped at heartbeat_interval).
  std::chrono::milliseconds poll_interval{20};
  std::chrono::milliseconds timeout_check_interval{250};
  // Work a worker that announces "prefetch" should hold, in render time (see credit above).
  std::chrono::milliseconds pipeline_target{100};
  std::chrono::milliseconds shutdown_linger{200};
  std::size_t max_message_bytes = 64u << 20;  // ZMQ_MAXMSGSIZE: larger messages drop the peer's connection
  // The bytes of a mesh asset's file (common/assets/mesh_file.h) by id, or
  // nullopt when there is no such asset; may throw (counted as a backend
  // error, answered ok=false).  Empty: every ASSET_GET is refused.
  std::function<std::optional<std::string>(const std::string& id)> asset_file;
  // Log lines ("worker w1 joined (4 slots)"); empty: standard error.
  std::function<void(std::string_view)> log;
};

// Counters since construction (thread-safe reads; "workers" is a gauge).
struct BrokerStats {
  std::uint64_t workers = 0;           // registered now
  std::uint64_t joined = 0;            // READY accepted
  std::uint64_t left = 0;              // worker_left calls (lost + disconnected)
  std::uint64_t lost = 0;              // of which: missed heartbeats or failed sends
  std::uint64_t rejected = 0;          // READY refused (version, worker id in use)
  std::uint64_t units_sent = 0;
  std::uint64_t results = 0;
  std::uint64_t failures = 0;          // FAILED messages
  std::uint64_t cancels_sent = 0;
  std::uint64_t malformed = 0;         // undecodable messages
  std::uint64_t unexpected = 0;        // valid messages a worker must not send (UNIT, CANCEL ...)
  std::uint64_t reregisters_sent = 0;
  std::uint64_t backend_errors = 0;    // exceptions thrown by the backend
  std::uint64_t auth_failures = 0;     // CURVE handshakes denied or failed (incl. rate-limited)
  std::uint64_t results_refused = 0;   // RESULT / FAILED for an attempt the worker was not sent
  std::uint64_t assets_served = 0;     // ASSET answers with the file
  std::uint64_t assets_refused = 0;    // ASSET answers without (unknown id, no store, read error)
};

class Broker {
 public:
  Broker(BrokerBackend& backend, BrokerOptions options = {});
  ~Broker();  // stop()
  Broker(const Broker&) = delete;
  Broker& operator=(const Broker&) = delete;

  // Binds the ROUTER (throws zmq::error_t or std::runtime_error when it
  // cannot) and starts the broker thread.  No-op while running.
  void start();
  // Idempotent; returns within about shutdown_linger + poll_interval.
  void stop();
  bool running() const { return thread_.joinable(); }
  // The endpoint actually bound (the port resolved), valid after start().
  std::string bound_endpoint() const;
  // Makes the broker thread dispatch now (e.g. after a job was submitted or
  // cancelled) instead of at its next poll tick.  Thread-safe, cheap.
  void wake();
  BrokerStats stats() const;

 private:
  struct Loop;
  struct Shared;
  BrokerBackend& backend_;
  BrokerOptions options_;
  std::unique_ptr<Shared> shared_;  // stop flag, wake-up pipe, counters
  std::unique_ptr<Loop> loop_;
  std::thread thread_;
  std::string bound_endpoint_;
};

}  // namespace skyfarm::server

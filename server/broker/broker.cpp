#include "server/broker/broker.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <set>
#include <iostream>
#include <map>
#include <unordered_map>
#include <vector>

#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "api/curve_keys.h"
#include "api/wire.h"
#include "common/core/wakeup_pipe.h"

namespace skyfarm::server {
namespace {

using Ms = std::chrono::milliseconds;

std::string printable(const std::string& bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : bytes.substr(0, 16)) {
    out += kHex[c >> 4];
    out += kHex[c & 15];
  }
  return out;
}

UnitKey key_of(const api::UnitRef& u) { return UnitKey{u.job, u.tile, u.batch, u.pass}; }

// Log the first ten, then every power of two: a flood cannot fill the log.
bool worth_logging(std::uint64_t n) { return n <= 10 || (n & (n - 1)) == 0; }

constexpr const char* kZapEndpoint = "inproc://zeromq.zap.01";  // fixed by the ZAP specification (RFC 27)
constexpr const char* kMonitorEndpoint = "inproc://skyfarm-broker-monitor";
constexpr const char* kZapDomain = "skyfarm-workers";
// A retired attempt cancelled here, remembered so its late answer is not a refusal.
constexpr std::size_t kMaxCancelledRemembered = 1024;

}  // namespace

struct Broker::Shared {
  std::atomic<bool> stop{false};
  WakeupPipe wakeup;
  std::atomic<std::uint64_t> workers{0}, joined{0}, left{0}, lost{0}, rejected{0}, units_sent{0}, results{0},
      failures{0}, cancels_sent{0}, malformed{0}, unexpected{0}, reregisters_sent{0}, backend_errors{0},
      auth_failures{0}, results_refused{0}, assets_served{0}, assets_refused{0};
};

// Everything the broker thread owns.  Built (and bound) in start() on the
// caller's thread, then used only by the broker thread (the thread start is
// the memory fence ZeroMQ asks for when a socket changes threads).
struct Broker::Loop {
  struct Worker {
    std::string identity;  // ROUTER routing id
    std::string id;        // READY "id"
    int slots = 1;
    int cores = 1;
    int prefetch = 0;      // READY "prefetch": extra credit it accepts
    double unit_s = -1.0;  // moving average of its RESULTs' render time (< 0: none yet)
    int credit = 1;        // units it may hold now: slots, up to slots + prefetch
    bool draining = false;
    std::map<std::uint64_t, UnitKey> in_flight;  // attempt -> unit
    std::set<std::uint64_t> cancelled;           // attempts taken back by CANCEL, answers still possible
    Clock::duration expiry_span{};
    Clock::time_point expiry{};
    Clock::time_point last_heard{};
    bool has_credit() const { return !draining && static_cast<int>(in_flight.size()) < credit; }
    // The credit for about `target_s` of work on its cores.
    void size_credit(double target_s) {
      credit = slots;
      if (prefetch <= 0 || unit_s < 0.0) return;
      const double want = std::ceil(target_s * std::max(1, cores) / std::max(unit_s, 1e-6));
      credit = static_cast<int>(std::clamp(want, static_cast<double>(slots), static_cast<double>(slots + prefetch)));
    }
  };

  Loop(BrokerBackend& backend, const BrokerOptions& options, Shared& shared)
      : backend_(backend), options_(options), shared_(shared), router_(ctx_, zmq::socket_type::router),
        auth_(options.auth, [this](const std::string& line) { log(line); }) {
    router_.set(zmq::sockopt::linger, 0);
    if (!options_.curve_secret_key.empty()) secure();
    router_.set(zmq::sockopt::router_mandatory, 1);
    router_.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(options_.max_message_bytes));
    router_.set(zmq::sockopt::sndtimeo, 0);
    router_.bind(options_.endpoint);
    bound_ = router_.get(zmq::sockopt::last_endpoint);
  }

  const std::string& bound() const { return bound_; }
  void run();

 private:
  // --- security
  void secure();
  void serve_zap();
  void read_monitor();
  void auth_failed(const std::string& what);
  // --- sending
  bool send(const std::string& identity, const api::Message& message);
  void send_or_lose(const std::string& identity, const api::Message& message);
  // --- receiving
  void receive_all();
  void handle(std::vector<zmq::message_t>& parts);
  void handle_ready(const std::string& identity, const api::ReadyMsg& ready);
  void handle_known(Worker& w, const api::Message& message);
  void handle_result(Worker& w, const api::ResultMsg& r);
  void handle_failed(Worker& w, const api::FailedMsg& f);
  void handle_asset_get(Worker& w, const api::AssetGetMsg& get);
  bool fenced(Worker& w, const api::UnitRef& u, const char* what);
  // --- workers
  void refuse(const std::string& identity, const std::string& reason);
  void register_worker(const std::string& identity, const api::ReadyMsg& ready);
  void remove_worker(const std::string& identity, const char* why, bool lost);
  Clock::duration expiry_span(int worker_heartbeat_ms) const;
  // --- periodic work
  void housekeeping(Clock::time_point now);
  void heartbeat_all();
  void expire(Clock::time_point now);
  void send_cancels();
  void dispatch();
  void shutdown();
  Ms poll_timeout(Clock::time_point now) const;
  template <class F>
  void guarded(const char* what, F&& f);
  void log(const std::string& line) const;

  BrokerBackend& backend_;
  const BrokerOptions& options_;
  Shared& shared_;
  zmq::context_t ctx_{1};
  zmq::socket_t router_;
  std::optional<zmq::socket_t> zap_, monitor_;
  WorkerAuth auth_;
  std::string bound_;
  std::map<std::string, Worker> workers_;                  // by identity
  std::unordered_map<std::string, std::string> identity_of_;  // worker id -> identity
  std::size_t round_robin_ = 0;
  Clock::time_point next_heartbeat_{}, next_timeout_check_{}, next_dispatch_{};
  bool dispatch_due_ = true;  // something may have made a unit or credit available
  bool behind_ = false;       // the last receive_all left messages in the socket
};

// --- Loop: main -----------------------------------------------------------------

void Broker::Loop::run() {
  const Clock::time_point start = Clock::now();
  next_heartbeat_ = start + options_.heartbeat_interval;
  next_timeout_check_ = start;
  while (!shared_.stop.load()) {
    zmq::pollitem_t items[] = {{router_.handle(), 0, ZMQ_POLLIN, 0},
                               {nullptr, shared_.wakeup.read_fd(), ZMQ_POLLIN, 0},
                               {zap_ ? zap_->handle() : nullptr, -1, ZMQ_POLLIN, 0},
                               {monitor_ ? monitor_->handle() : nullptr, -1, ZMQ_POLLIN, 0}};
    try {
      zmq::poll(items, zap_ ? 4 : 2, poll_timeout(Clock::now()));
      if (items[1].revents & ZMQ_POLLIN) {
        shared_.wakeup.drain();
        dispatch_due_ = true;
      }
      if (zap_ && (items[2].revents & ZMQ_POLLIN)) serve_zap();
      if (monitor_ && (items[3].revents & ZMQ_POLLIN)) read_monitor();
      if (items[0].revents & ZMQ_POLLIN) receive_all();
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) {
        log(std::string("broker: ZeroMQ error, stopping: ") + e.what());
        break;
      }
    }
    if (shared_.stop.load()) break;
    housekeeping(Clock::now());
  }
  shutdown();
}

Ms Broker::Loop::poll_timeout(Clock::time_point now) const {
  const Ms tick = std::min(options_.poll_interval, options_.heartbeat_interval);
  const auto to_heartbeat = std::chrono::duration_cast<Ms>(next_heartbeat_ - now);
  return std::clamp(to_heartbeat, Ms(0), std::max(tick, Ms(1)));
}

void Broker::Loop::housekeeping(Clock::time_point now) {
  expire(now);
  if (now >= next_heartbeat_) {
    heartbeat_all();
    next_heartbeat_ = now + options_.heartbeat_interval;
  }
  send_cancels();
  if (now >= next_timeout_check_) {
    guarded("check_timeouts", [&] { backend_.check_timeouts(now); });
    next_timeout_check_ = now + options_.timeout_check_interval;
    dispatch_due_ = true;
  }
  if (dispatch_due_ || now >= next_dispatch_) {
    dispatch_due_ = false;
    next_dispatch_ = now + options_.poll_interval;
    dispatch();
  }
}

void Broker::Loop::shutdown() {
  const api::Message bye = api::DisconnectMsg{"server shutting down", false};
  std::vector<std::string> identities;
  for (const auto& [identity, w] : workers_) identities.push_back(identity);
  for (const auto& identity : identities) {
    send(identity, bye);
    remove_worker(identity, "server shutting down", false);
  }
  try {
    router_.set(zmq::sockopt::linger, static_cast<int>(options_.shutdown_linger.count()));
  } catch (const zmq::error_t&) {
  }
  router_.close();
  if (monitor_) monitor_->close();
  if (zap_) zap_->close();
}

// --- Loop: security -----------------------------------------------------------------

// Before the bind: the ZAP handler must exist before the first handshake, or
// libzmq would let the client in unchecked.
void Broker::Loop::secure() {
  if (!zmq_has("curve")) throw std::runtime_error("this libzmq has no CURVE support");
  zap_.emplace(ctx_, zmq::socket_type::rep);
  zap_->set(zmq::sockopt::linger, 0);
  zap_->bind(kZapEndpoint);
  router_.set(zmq::sockopt::curve_server, 1);
  router_.set(zmq::sockopt::curve_secretkey, options_.curve_secret_key);
  router_.set(zmq::sockopt::zap_domain, kZapDomain);
  // ZAP denials are counted where they are decided; the monitor sees the
  // handshakes that never reach ZAP (a client speaking another mechanism).
  if (zmq_socket_monitor(router_.handle(), kMonitorEndpoint,
                         ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL | ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) != 0)
    throw zmq::error_t();
  monitor_.emplace(ctx_, zmq::socket_type::pair);
  monitor_->set(zmq::sockopt::linger, 0);
  monitor_->connect(kMonitorEndpoint);
}

void Broker::Loop::auth_failed(const std::string& what) {
  const auto n = ++shared_.auth_failures;
  if (worth_logging(n)) log("broker: worker authentication failed: " + what + " (" + std::to_string(n) + " so far)");
}

// ZAP (RFC 27): [version, request id, domain, address, identity, mechanism,
// credentials...] -> [version, request id, status code, status text, user id, metadata].
void Broker::Loop::serve_zap() {
  for (int i = 0; i < 1000; ++i) {
    std::vector<zmq::message_t> request;
    if (!zmq::recv_multipart(*zap_, std::back_inserter(request), zmq::recv_flags::dontwait)) return;
    WorkerAuth::Decision decision{false, "malformed ZAP request"};
    std::string address = "?", key;
    if (request.size() >= 6 && request[0].to_string() == "1.0") {
      address = request[3].to_string();
      const std::string mechanism = request[5].to_string();
      if (mechanism == "CURVE" && request.size() >= 7 && request[6].size() == 32) {
        key = api::z85_encode_key(request[6].to_string());
        decision = auth_.check(address, key, Clock::now());
      } else {
        decision.reason = "mechanism " + mechanism + " not accepted";
        auth_.charge(address, Clock::now());
      }
    }
    if (!decision.allowed) auth_failed(decision.reason + " (from " + address + ")");
    const std::string id = request.size() > 1 ? request[1].to_string() : std::string();
    const std::array<std::string, 6> reply = {"1.0", id, decision.allowed ? "200" : "400",
                                              decision.allowed ? "OK" : decision.reason,
                                              decision.allowed ? key : std::string(), ""};
    try {
      for (std::size_t f = 0; f < reply.size(); ++f)
        zap_->send(zmq::buffer(reply[f]), f + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    } catch (const zmq::error_t& e) {
      log(std::string("broker: cannot answer a ZAP request: ") + e.what());
    }
  }
}

// Monitor events: [16-bit event, 32-bit value] [endpoint].
void Broker::Loop::read_monitor() {
  for (int i = 0; i < 1000; ++i) {
    std::vector<zmq::message_t> event;
    if (!zmq::recv_multipart(*monitor_, std::back_inserter(event), zmq::recv_flags::dontwait)) return;
    if (event.empty() || event[0].size() < 6) continue;
    std::uint16_t id = 0;
    std::memcpy(&id, event[0].data(), sizeof id);
    if (id == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL) auth_failed("a client failed the CURVE handshake (wrong mechanism or key)");
    else if (id == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) auth_failed("a client's handshake failed");
  }
}

// --- Loop: sending ----------------------------------------------------------------

// Never blocks: false when the peer is gone (EHOSTUNREACH under
// ROUTER_MANDATORY) or its queue is full (EAGAIN).  Only the identity frame
// can fail; the rest of a message follows it atomically.
bool Broker::Loop::send(const std::string& identity, const api::Message& message) {
  const api::Frames frames = api::encode(message);
  try {
    if (!router_.send(zmq::buffer(identity), zmq::send_flags::sndmore | zmq::send_flags::dontwait)) return false;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const auto more = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      (void)router_.send(zmq::buffer(frames[i]), more | zmq::send_flags::dontwait);
    }
    return true;
  } catch (const zmq::error_t& e) {
    if (e.num() != EHOSTUNREACH) log(std::string("broker: send failed: ") + e.what());
    return false;
  }
}

void Broker::Loop::send_or_lose(const std::string& identity, const api::Message& message) {
  if (!send(identity, message) && workers_.count(identity)) remove_worker(identity, "unreachable", true);
}

// --- Loop: receiving --------------------------------------------------------------

void Broker::Loop::receive_all() {
  // Bounded, so a flood cannot starve heartbeats and dispatch.
  behind_ = true;
  for (int i = 0; i < 1000 && !shared_.stop.load(); ++i) {
    std::vector<zmq::message_t> parts;
    if (!zmq::recv_multipart(router_, std::back_inserter(parts), zmq::recv_flags::dontwait)) {
      behind_ = false;
      return;
    }
    handle(parts);
  }
}

void Broker::Loop::handle(std::vector<zmq::message_t>& parts) {
  if (parts.empty()) return;
  const std::string identity = parts[0].to_string();
  api::Frames frames;
  frames.reserve(parts.size() - 1);
  for (std::size_t i = 1; i < parts.size(); ++i) frames.push_back(parts[i].to_string());
  const auto known = workers_.find(identity);
  if (known != workers_.end()) {
    known->second.last_heard = Clock::now();
    known->second.expiry = known->second.last_heard + known->second.expiry_span;
  }

  std::string error;
  const std::optional<api::Message> message = api::try_decode(frames, &error);
  if (!message) {
    const auto n = ++shared_.malformed;
    if (worth_logging(n))
      log("broker: dropped a malformed message from peer " + printable(identity) + ": " + error + " (" +
          std::to_string(n) + " so far)");
    return;
  }
  if (const auto* ready = std::get_if<api::ReadyMsg>(&*message)) {
    handle_ready(identity, *ready);
  } else if (known != workers_.end()) {
    handle_known(known->second, *message);
  } else if (!std::holds_alternative<api::DisconnectMsg>(*message)) {
    // A peer we do not know (we restarted, or declared it lost): ask it to READY again.
    if (send(identity, api::ReregisterMsg{})) ++shared_.reregisters_sent;
  }
}

void Broker::Loop::handle_ready(const std::string& identity, const api::ReadyMsg& ready) {
  if (ready.version != api::kProtocolVersion) {
    refuse(identity, "protocol version " + std::to_string(ready.version) + " not supported (server speaks " +
                         std::to_string(api::kProtocolVersion) + ")");
    return;
  }
  // The token (if any) is not checked: the worker proved itself in the CURVE handshake.
  if (const auto it = identity_of_.find(ready.id); it != identity_of_.end() && it->second != identity) {
    const Worker& holder = workers_.at(it->second);
    const auto interval = holder.expiry_span / std::max(1, options_.heartbeat_liveness);
    if (Clock::now() - holder.last_heard < 2 * interval) {
      refuse(identity, "worker id in use: " + ready.id);
      return;
    }
    remove_worker(it->second, "reconnected", false);
  }
  if (workers_.count(identity)) remove_worker(identity, "sent READY again", false);
  register_worker(identity, ready);
}

void Broker::Loop::handle_known(Worker& w, const api::Message& message) {
  if (const auto* hb = std::get_if<api::HeartbeatMsg>(&message)) {
    if (hb->draining && !w.draining) log("broker: worker " + w.id + " is draining");
    w.draining = w.draining || hb->draining;
    if (hb->heartbeat_ms > 0) w.expiry_span = expiry_span(hb->heartbeat_ms);
  } else if (const auto* r = std::get_if<api::ResultMsg>(&message)) {
    handle_result(w, *r);
  } else if (const auto* f = std::get_if<api::FailedMsg>(&message)) {
    handle_failed(w, *f);
  } else if (const auto* get = std::get_if<api::AssetGetMsg>(&message)) {
    handle_asset_get(w, *get);
  } else if (std::holds_alternative<api::DisconnectMsg>(message)) {
    remove_worker(w.identity, "disconnected", false);
  } else {
    ++shared_.unexpected;
  }
}

// True when `u` is an attempt `w` holds (it leaves w's in-flight set);
// otherwise the answer is refused and counted, and nothing changes.
bool Broker::Loop::fenced(Worker& w, const api::UnitRef& u, const char* what) {
  const auto it = w.in_flight.find(u.attempt);
  if (it != w.in_flight.end() && it->second == key_of(u)) {
    w.in_flight.erase(it);
    return true;
  }
  if (it == w.in_flight.end() && w.cancelled.erase(u.attempt)) return false;  // cancelled here: a late answer
  const auto n = ++shared_.results_refused;
  if (worth_logging(n))
    log(std::string("broker: refused a ") + what + " from worker " + w.id + " for attempt " +
        std::to_string(u.attempt) + " (" + u.job + "/" + std::to_string(u.tile) + "/" + std::to_string(u.batch) + "/" +
        std::to_string(u.pass) + "): " + (it == w.in_flight.end() ? "not sent to it" : "not the unit sent") + " (" +
        std::to_string(n) + " so far)");
  return false;
}

void Broker::Loop::handle_result(Worker& w, const api::ResultMsg& r) {
  if (!fenced(w, r.unit, "RESULT")) return;
  ++shared_.results;
  // The fence took the attempt off the worker: its credit is sized from the
  // render time it reports (a worker's own word, so only a sane one counts).
  if (std::isfinite(r.seconds) && r.seconds >= 0.0) {
    w.unit_s = w.unit_s < 0.0 ? r.seconds : 0.8 * w.unit_s + 0.2 * r.seconds;
    w.size_credit(std::chrono::duration<double>(options_.pipeline_target).count());
  }
  dispatch_due_ = true;
  guarded("unit_done", [&] {
    backend_.unit_done(w.id, key_of(r.unit), r.unit.attempt, api::payload_bytes(r.film_tile), r.paths);
  });
}

void Broker::Loop::handle_failed(Worker& w, const api::FailedMsg& f) {
  if (!fenced(w, f.unit, "FAILED")) return;
  ++shared_.failures;
  dispatch_due_ = true;
  log("broker: worker " + w.id + " failed unit " + f.unit.job + "/" + std::to_string(f.unit.tile) + "/" +
      std::to_string(f.unit.batch) + "/" + std::to_string(f.unit.pass) + ": " + f.message);
  guarded("unit_failed", [&] { backend_.unit_failed(w.id, key_of(f.unit), f.unit.attempt, f.message); });
}

void Broker::Loop::handle_asset_get(Worker& w, const api::AssetGetMsg& get) {
  api::AssetMsg answer{get.id, false, "", ""};
  std::optional<std::string> file;
  if (options_.asset_file) guarded("asset_file", [&] { file = options_.asset_file(get.id); });
  if (file && !file->empty()) {
    answer.ok = true;
    answer.file = std::move(*file);
    ++shared_.assets_served;
    log("broker: sent asset " + get.id + " (" + std::to_string(answer.file.size()) + " bytes) to worker " + w.id);
  } else {
    answer.error = options_.asset_file ? "no asset " + get.id + " on this server (upload it: POST /v1/assets)"
                                       : "this server has no asset store (asset " + get.id + ")";
    const auto n = ++shared_.assets_refused;
    if (worth_logging(n))
      log("broker: worker " + w.id + " asked for asset " + get.id + ", which is not here (" + std::to_string(n) +
          " so far)");
  }
  send_or_lose(w.identity, answer);
}

// --- Loop: workers ------------------------------------------------------------------

void Broker::Loop::refuse(const std::string& identity, const std::string& reason) {
  ++shared_.rejected;
  log("broker: refused a worker: " + reason);
  send(identity, api::DisconnectMsg{reason, true});
  if (workers_.count(identity)) remove_worker(identity, "refused", false);
}

Clock::duration Broker::Loop::expiry_span(int worker_heartbeat_ms) const {
  const Ms interval = std::max(options_.heartbeat_interval, Ms(worker_heartbeat_ms));
  return interval * std::max(1, options_.heartbeat_liveness);
}

void Broker::Loop::register_worker(const std::string& identity, const api::ReadyMsg& ready) {
  Worker w;
  w.identity = identity;
  w.id = ready.id;
  w.slots = ready.slots;
  w.cores = ready.cores;
  w.prefetch = ready.prefetch;
  w.credit = ready.slots;
  w.expiry_span = expiry_span(ready.heartbeat_ms);
  w.last_heard = Clock::now();
  w.expiry = w.last_heard + w.expiry_span;
  workers_[identity] = w;
  identity_of_[ready.id] = identity;
  dispatch_due_ = true;
  ++shared_.workers;
  ++shared_.joined;
  nlohmann::json info{{"id", ready.id},
                      {"cores", ready.cores},
                      {"slots", ready.slots},
                      {"version", ready.version},
                      {"capabilities", ready.capabilities}};
  if (ready.heartbeat_ms > 0) info["heartbeat_ms"] = ready.heartbeat_ms;
  log("broker: worker " + ready.id + " joined (" + std::to_string(ready.cores) + " cores, " +
      std::to_string(ready.slots) + " slots)");
  guarded("worker_joined", [&] { backend_.worker_joined(ready.id, info); });
  send_or_lose(identity, api::HeartbeatMsg{static_cast<int>(options_.heartbeat_interval.count()), false});
}

void Broker::Loop::remove_worker(const std::string& identity, const char* why, bool lost) {
  const auto it = workers_.find(identity);
  if (it == workers_.end()) return;
  const std::string id = it->second.id;
  const std::size_t held = it->second.in_flight.size();
  workers_.erase(it);
  if (const auto i = identity_of_.find(id); i != identity_of_.end() && i->second == identity) identity_of_.erase(i);
  --shared_.workers;
  ++shared_.left;
  dispatch_due_ = true;  // its units are requeued
  if (lost) ++shared_.lost;
  log("broker: worker " + id + " left (" + why + ", " + std::to_string(held) + " units in flight)");
  guarded("worker_left", [&] { backend_.worker_left(id); });
}

// --- Loop: periodic work -----------------------------------------------------------

void Broker::Loop::heartbeat_all() {
  const api::Message hb = api::HeartbeatMsg{static_cast<int>(options_.heartbeat_interval.count()), false};
  std::vector<std::string> unreachable;
  for (const auto& [identity, w] : workers_)
    if (!send(identity, hb)) unreachable.push_back(identity);
  for (const auto& identity : unreachable) remove_worker(identity, "unreachable", true);
}

void Broker::Loop::expire(Clock::time_point now) {
  // Behind on its input, the broker cannot tell a silent worker from one
  // whose messages wait in the socket: a loaded broker must not drop live workers.
  if (behind_) return;
  std::vector<std::string> expired;
  for (const auto& [identity, w] : workers_)
    if (w.expiry < now) expired.push_back(identity);
  for (const auto& identity : expired) remove_worker(identity, "missed heartbeats", true);
}

void Broker::Loop::send_cancels() {
  std::vector<std::pair<std::string, std::uint64_t>> cancels;
  guarded("take_cancelled_attempts", [&] { cancels = backend_.take_cancelled_attempts(); });
  for (const auto& [worker_id, attempt] : cancels) {
    const auto i = identity_of_.find(worker_id);
    if (i == identity_of_.end()) continue;  // gone: nothing to stop
    const std::string identity = i->second;
    Worker& w = workers_.at(identity);
    if (!w.in_flight.erase(attempt)) continue;  // already answered
    if (w.cancelled.size() >= kMaxCancelledRemembered) w.cancelled.erase(w.cancelled.begin());
    w.cancelled.insert(attempt);
    ++shared_.cancels_sent;
    dispatch_due_ = true;
    send_or_lose(identity, api::CancelMsg{attempt});
  }
}

void Broker::Loop::dispatch() {
  // Round-robin rounds of one unit per worker with credit, until nobody can
  // take one or the backend has nothing for anyone.
  for (bool progress = true; progress && !shared_.stop.load();) {
    progress = false;
    // Pointers into workers_ (a map: removing one worker leaves the others in place).
    std::vector<Worker*> ready;
    ready.reserve(workers_.size());
    for (auto& [identity, w] : workers_)
      if (w.has_credit()) ready.push_back(&w);
    if (ready.empty()) return;
    std::rotate(ready.begin(), ready.begin() + static_cast<std::ptrdiff_t>(round_robin_++ % ready.size()), ready.end());
    for (Worker* wp : ready) {
      Worker& w = *wp;
      if (!w.has_credit()) continue;
      const std::string& identity = w.identity;
      std::optional<UnitAssignment> unit;
      guarded("next_unit", [&] { unit = backend_.next_unit(w.id); });
      if (!unit) continue;
      w.in_flight[unit->attempt] = unit->key;
      api::UnitMsg msg{{unit->key.job_id, unit->key.tile, unit->key.batch, unit->key.pass, unit->attempt},
                       std::move(unit->request_canonical), unit->kind, std::move(unit->samples_per_pass)};
      if (!send(identity, msg)) {
        const std::string gone = identity;
        remove_worker(gone, "unreachable", true);  // the backend requeues the unit
        continue;
      }
      ++shared_.units_sent;
      progress = true;
    }
  }
}

template <class F>
void Broker::Loop::guarded(const char* what, F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    ++shared_.backend_errors;
    log(std::string("broker: backend ") + what + " threw: " + e.what());
  }
}

void Broker::Loop::log(const std::string& line) const {
  if (options_.log) options_.log(line);
  else std::cerr << line << "\n";
}

// --- Broker ------------------------------------------------------------------------

Broker::Broker(BrokerBackend& backend, BrokerOptions options)
    : backend_(backend), options_(std::move(options)), shared_(std::make_unique<Shared>()) {
  if (options_.heartbeat_interval <= Ms(0)) options_.heartbeat_interval = Ms(1000);
  if (options_.heartbeat_liveness < 1) options_.heartbeat_liveness = 1;
  if (options_.poll_interval <= Ms(0)) options_.poll_interval = Ms(20);
}

Broker::~Broker() { stop(); }

void Broker::start() {
  if (thread_.joinable()) return;
  shared_->stop.store(false);
  loop_ = std::make_unique<Loop>(backend_, options_, *shared_);
  bound_endpoint_ = loop_->bound();
  thread_ = std::thread([loop = loop_.get()] { loop->run(); });
}

void Broker::stop() {
  if (!thread_.joinable()) return;
  shared_->stop.store(true);
  shared_->wakeup.notify();
  thread_.join();
  loop_.reset();  // terminates the context: waits at most shutdown_linger
}

std::string Broker::bound_endpoint() const { return bound_endpoint_; }

void Broker::wake() { shared_->wakeup.notify(); }

BrokerStats Broker::stats() const {
  const Shared& s = *shared_;
  return BrokerStats{s.workers.load(),    s.joined.load(),       s.left.load(),         s.lost.load(),
                     s.rejected.load(),   s.units_sent.load(),   s.results.load(),      s.failures.load(),
                     s.cancels_sent.load(), s.malformed.load(),  s.unexpected.load(),   s.reregisters_sent.load(),
                     s.backend_errors.load(), s.auth_failures.load(), s.results_refused.load(),
                     s.assets_served.load(),  s.assets_refused.load()};
}

}  // namespace skyfarm::server

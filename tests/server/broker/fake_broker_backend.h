// A BrokerBackend for the broker and farm-worker tests: a FIFO of units,
// attempts numbered from 1, a record of every call, the units each worker
// holds (requeued when it leaves), and waiting helpers with deadlines.
#pragma once
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "api/curve_keys.h"
#include "api/render_request.h"
#include "api/wire.h"
#include "server/broker/broker_backend.h"

namespace skyfarm::testing {

// A 16x8 equirectangular sky with 2 spp in 2 wavelength batches; width 48
// gives 2 tiles (4 units), 16 gives 1 tile (2 units).
inline std::string tiny_request(int width = 48) {
  const std::string body = R"({"sun": {"zenith_deg": 60, "azimuth_deg": 120},
      "camera": {"projection": "equirectangular", "width": )" + std::to_string(width) + R"(, "height": 8},
      "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 2}})";
  return api::canonical_text(api::parse_render_request(body));
}

// Polls `pred` every 5 ms until it holds (true) or `timeout` passes (false).
template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

class FakeBackend : public server::BrokerBackend {
 public:
  struct Done {
    std::string worker;
    server::UnitKey key;
    std::uint64_t attempt = 0;
    std::vector<std::uint8_t> bytes;
    std::uint64_t paths = 0;
  };
  struct Failed {
    std::string worker;
    server::UnitKey key;
    std::uint64_t attempt = 0;
    std::string message;
  };
  struct Dispatch {
    std::string worker;
    server::UnitAssignment unit;
  };

  // --- test side
  void add_unit(const std::string& job, int tile, int batch, int pass, const std::string& request) {
    std::lock_guard lock(mutex_);
    queue_.push_back(server::UnitAssignment{server::UnitKey{job, tile, batch, pass}, 0, request});
  }
  // Every unit of `request`'s plan (canonical order), as job `job`.
  void add_units(const std::string& job, int tiles, int batches, int passes, const std::string& request) {
    for (int t = 0; t < tiles; ++t)
      for (int p = 0; p < passes; ++p)
        for (int b = 0; b < batches; ++b) add_unit(job, t, b, p, request);
  }
  // Asks the broker to cancel an attempt (its holder as the JobService would name it).
  void cancel(std::uint64_t attempt) {
    std::lock_guard lock(mutex_);
    const auto it = dispatched_.find(attempt);
    if (it != dispatched_.end()) cancels_.emplace_back(it->second.worker, attempt);
  }
  void set_dispatch_enabled(bool enabled) {
    std::lock_guard lock(mutex_);
    dispatch_enabled_ = enabled;
  }

  template <class Pred>
  bool wait_for(Pred pred, std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return pred(*this); });
  }
  template <class F>
  auto with_lock(F f) {
    std::lock_guard lock(mutex_);
    return f(*this);
  }

  // Read these under with_lock / wait_for.
  std::vector<std::pair<std::string, nlohmann::json>> joined;
  std::vector<std::string> left;
  std::vector<Done> done;
  std::vector<Failed> failed;
  std::vector<Dispatch> dispatches;          // every next_unit that returned a unit
  std::vector<std::string> events;           // "joined:W", "left:W", "done:ATTEMPT", "failed:ATTEMPT"
  std::map<std::string, int> max_held;       // per worker, the most units held at once
  std::deque<server::UnitAssignment> queue_;  // waiting units
  std::map<std::uint64_t, Dispatch> dispatched_;  // attempt -> holder, until done/failed/left/cancelled
  int held(const std::string& worker) const {
    int n = 0;
    for (const auto& [a, d] : dispatched_) n += d.worker == worker;
    return n;
  }

  // --- BrokerBackend
  void worker_joined(const std::string& id, const nlohmann::json& info) override {
    notify([&] {
      joined.emplace_back(id, info);
      events.push_back("joined:" + id);
    });
  }
  void worker_left(const std::string& id) override {
    notify([&] {
      left.push_back(id);
      events.push_back("left:" + id);
      for (auto it = dispatched_.begin(); it != dispatched_.end();) {
        if (it->second.worker == id) {
          queue_.push_front(server::UnitAssignment{it->second.unit.key, 0, it->second.unit.request_canonical});
          it = dispatched_.erase(it);
        } else {
          ++it;
        }
      }
    });
  }
  std::optional<server::UnitAssignment> next_unit(const std::string& worker) override {
    std::optional<server::UnitAssignment> out;
    notify([&] {
      if (!dispatch_enabled_ || queue_.empty()) return;
      server::UnitAssignment a = queue_.front();
      queue_.pop_front();
      a.attempt = next_attempt_++;
      dispatched_[a.attempt] = Dispatch{worker, a};
      dispatches.push_back(Dispatch{worker, a});
      max_held[worker] = std::max(max_held[worker], held(worker));
      out = a;
    });
    return out;
  }
  void unit_done(const std::string& worker, const server::UnitKey& key, std::uint64_t attempt,
                 const std::vector<std::uint8_t>& bytes, std::uint64_t paths) override {
    notify([&] {
      done.push_back(Done{worker, key, attempt, bytes, paths});
      events.push_back("done:" + std::to_string(attempt));
      dispatched_.erase(attempt);
    });
  }
  void unit_failed(const std::string& worker, const server::UnitKey& key, std::uint64_t attempt,
                   const std::string& message) override {
    notify([&] {
      failed.push_back(Failed{worker, key, attempt, message});
      events.push_back("failed:" + std::to_string(attempt));
      dispatched_.erase(attempt);
    });
  }
  std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts() override {
    std::lock_guard lock(mutex_);
    for (const auto& [w, a] : cancels_) dispatched_.erase(a);
    return std::exchange(cancels_, {});
  }
  void check_timeouts(server::Clock::time_point) override {}

 private:
  template <class F>
  void notify(F f) {
    {
      std::lock_guard lock(mutex_);
      f();
    }
    cv_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t next_attempt_ = 1;
  bool dispatch_enabled_ = true;
  std::vector<std::pair<std::string, std::uint64_t>> cancels_;
};

// A raw DEALER peer speaking api/wire.h, for driving the broker by hand.
class RawPeer {
 public:
  RawPeer(zmq::context_t& ctx, const std::string& endpoint) : socket_(ctx, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.connect(endpoint);
  }
  // A CURVE client with key pair `own` of a server whose public key is `server_key` (Z85).
  RawPeer(zmq::context_t& ctx, const std::string& endpoint, const api::CurveKeyPair& own, const std::string& server_key)
      : socket_(ctx, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.set(zmq::sockopt::curve_serverkey, server_key);
    socket_.set(zmq::sockopt::curve_publickey, own.public_key);
    socket_.set(zmq::sockopt::curve_secretkey, own.secret_key);
    socket_.connect(endpoint);
  }
  void send_frames(const api::Frames& frames) {
    for (std::size_t i = 0; i < frames.size(); ++i)
      socket_.send(zmq::buffer(frames[i]), i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
  }
  void send(const api::Message& m) { send_frames(api::encode(m)); }
  // The next message (decoded), or nullopt after `timeout`.
  std::optional<api::Message> receive(std::chrono::milliseconds timeout = std::chrono::milliseconds(2000)) {
    zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
    if (zmq::poll(&item, 1, timeout) <= 0) return std::nullopt;
    std::vector<zmq::message_t> parts;
    if (!zmq::recv_multipart(socket_, std::back_inserter(parts))) return std::nullopt;
    api::Frames frames;
    for (auto& p : parts) frames.push_back(p.to_string());
    return api::decode(frames);
  }
  // The next message of type T, skipping others (heartbeats); nullopt after `timeout`.
  template <class T>
  std::optional<T> receive_a(std::chrono::milliseconds timeout = std::chrono::milliseconds(2000)) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      auto m = receive(left);
      if (!m) return std::nullopt;
      if (auto* t = std::get_if<T>(&*m)) return *t;
    }
  }
  static api::ReadyMsg ready(const std::string& id, int slots = 1) {
    api::ReadyMsg r;
    r.id = id;
    r.cores = 1;
    r.slots = slots;
    r.capabilities = {{"spectral", true}};
    return r;
  }
  zmq::socket_t& socket() { return socket_; }

 private:
  zmq::socket_t socket_;
};

}  // namespace skyfarm::testing

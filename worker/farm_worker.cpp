#include "worker/farm_worker.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <optional>
#include <cstdio>
#include <deque>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "api/wire.h"
#include "common/core/wakeup_pipe.h"
#include "common/film/film_tile.h"
#include "common/render/parallel.h"
#include "common/render/tile_renderer.h"
#include "worker/asset_cache.h"
#include "worker/asset_requests.h"
#include "worker/mesh_cache.h"
#include "worker/volume_cache.h"
#include "worker/probe_unit.h"
#include "worker/setup_cache.h"

namespace skyfarm {
namespace {

using Clock = std::chrono::steady_clock;
using Ms = std::chrono::milliseconds;

constexpr Ms kMaxTick{100};  // longest poll: latency of drain_flag and of pause changes

// --- Setups ---------------------------------------------------------------------

// What renders the units of one render job.
struct JobRenderer {
  RenderSetup setup;
  std::unique_ptr<TileRenderer> renderer;
};

JobRenderer make_job_renderer(const std::string& request_text, const assets::MeshSource* meshes,
                              const assets::VolumeSource* volumes) {
  try {
    const api::RenderRequest request = api::parse_render_request(request_text);
    JobRenderer job;
    job.setup = make_render_setup(api::render_spec(request), meshes, volumes);
    job.renderer = std::make_unique<TileRenderer>(*job.setup.scene, *job.setup.camera, job.setup.plan);
    return job;
  } catch (const api::ValidationError& ex) {
    throw std::runtime_error(std::string("invalid request: ") + ex.what());
  } catch (const AssetUnavailable& ex) {
    throw TransientSetupError(std::string("cannot set up the render: ") + ex.what());
  } catch (const std::exception& ex) {
    throw std::runtime_error(std::string("cannot set up the render: ") + ex.what());
  }
}

// The setups of render jobs and of probes, each an LRU of setup_cache_jobs.
struct Setups {
  Setups(std::size_t jobs, const assets::MeshSource* meshes, const assets::VolumeSource* volumes)
      : renders(jobs,
                [meshes, volumes](const std::string& request) { return make_job_renderer(request, meshes, volumes); }),
        probes(jobs, make_probe_setup) {}
  SetupCache<JobRenderer> renders;
  SetupCache<ProbeSetup> probes;
};

// --- Render pool ------------------------------------------------------------------

struct RenderTask {
  std::uint64_t session = 0;
  api::UnitMsg unit;
};

struct RenderOutcome {
  std::uint64_t session = 0;
  std::uint64_t attempt = 0;
  api::Message message;  // ResultMsg or FailedMsg
};

api::Message render_unit_message(Setups& setups, const api::UnitMsg& task) {
  const auto t0 = Clock::now();
  try {
    if (task.kind == api::UnitKind::kProbe)
      return run_probe_unit(*setups.probes.get(task.unit.job, task.request), task);
    const auto job = setups.renders.get(task.unit.job, task.request);
    const RenderPlan& plan = job->renderer->plan();
    const api::UnitRef& u = task.unit;
    if (u.tile >= plan.tile_count() || u.batch >= plan.batches || u.pass >= plan.passes)
      throw std::runtime_error("unit (tile " + std::to_string(u.tile) + ", batch " + std::to_string(u.batch) +
                               ", pass " + std::to_string(u.pass) + ") is outside the job's plan");
    // An adaptive job's later passes need their counts, one per allocation
    // block of the tile, and only they take any.
    const bool counted = !task.samples_per_pass.empty();
    if (counted != (plan.adaptive && u.pass > 0))
      throw std::runtime_error("unit (tile " + std::to_string(u.tile) + ", pass " + std::to_string(u.pass) + ") " +
                               (counted ? "has samples_per_pass, but its plan allocates none there"
                                        : "of an adaptive plan after its pilot has no samples_per_pass"));
    if (counted && static_cast<int>(task.samples_per_pass.size()) != plan.block_count(u.tile))
      throw std::runtime_error("unit (tile " + std::to_string(u.tile) + ") has samples_per_pass for " +
                               std::to_string(task.samples_per_pass.size()) + " blocks; the tile has " +
                               std::to_string(plan.block_count(u.tile)));
    WorkUnit unit{u.tile, u.batch, u.pass, {}};
    for (const auto& [even, odd] : task.samples_per_pass) unit.samples.push_back({even, odd});
    FilmTile film = job->renderer->empty_tile(u.tile);
    PathCounters counters;
    job->renderer->render_unit(unit, &film, &counters);
    const std::vector<std::uint8_t> bytes = film.serialize();
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return api::ResultMsg{u, counters.paths, seconds, std::string(bytes.begin(), bytes.end())};
  } catch (const std::exception& e) {
    return api::FailedMsg{task.unit, e.what()};
  }
}

// `threads` render threads taking tasks in arrival order; outcomes are queued
// for the I/O thread, which is woken through the pipe.
class RenderPool {
 public:
  RenderPool(int threads, std::size_t cache_jobs, const assets::MeshSource* meshes,
             const assets::VolumeSource* volumes, const WakeupPipe& wakeup)
      : setups_(cache_jobs, meshes, volumes), wakeup_(wakeup) {
    for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { work(); });
  }
  ~RenderPool() { stop(); }

  void push(RenderTask task) {
    {
      std::lock_guard lock(mutex_);
      tasks_.push_back(std::move(task));
    }
    cv_.notify_one();
  }
  // Drops a task that has not started; false if none matched.
  bool remove(std::uint64_t session, std::uint64_t attempt) {
    std::lock_guard lock(mutex_);
    const auto it = std::find_if(tasks_.begin(), tasks_.end(), [&](const RenderTask& t) {
      return t.session == session && t.unit.unit.attempt == attempt;
    });
    if (it == tasks_.end()) return false;
    tasks_.erase(it);
    return true;
  }
  void clear_queue() {
    std::lock_guard lock(mutex_);
    tasks_.clear();
  }
  std::vector<RenderOutcome> take_outcomes() {
    std::lock_guard lock(mutex_);
    std::vector<RenderOutcome> out(std::make_move_iterator(outcomes_.begin()), std::make_move_iterator(outcomes_.end()));
    outcomes_.clear();
    return out;
  }
  // Units in progress finish first (render_unit cannot be interrupted).
  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      tasks_.clear();
    }
    cv_.notify_all();
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }

 private:
  void work() {
    for (;;) {
      RenderTask task;
      {
        std::unique_lock lock(mutex_);
        cv_.wait(lock, [&] { return stopping_ || !tasks_.empty(); });
        if (stopping_) return;
        task = std::move(tasks_.front());
        tasks_.pop_front();
      }
      RenderOutcome outcome{task.session, task.unit.unit.attempt, render_unit_message(setups_, task.unit)};
      {
        std::lock_guard lock(mutex_);
        outcomes_.push_back(std::move(outcome));
      }
      wakeup_.notify();
    }
  }

  Setups setups_;
  const WakeupPipe& wakeup_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<RenderTask> tasks_;
  std::deque<RenderOutcome> outcomes_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

// How a session (one socket's life) ended.
enum class SessionEnd { kDrained, kRefused, kServerGone };

}  // namespace

// --- FarmWorker::Impl -----------------------------------------------------------------

struct FarmWorker::Impl {
  explicit Impl(FarmWorkerOptions o);

  int run();
  bool drain_requested() const {
    return drain.load() || (options.drain_flag != nullptr && options.drain_flag->load());
  }

  FarmWorkerOptions options;
  int threads = 1;
  int slots = 2;
  std::atomic<bool> drain{false};
  std::atomic<bool> paused{false};
  std::atomic<bool> running{false};
  std::atomic<bool> stopping{false};  // run() is returning: no more asset questions
  WakeupPipe wakeup;
  struct Counters {
    std::atomic<std::uint64_t> sessions{0}, units_received{0}, results_sent{0}, failures_sent{0},
        cancels_received{0}, results_dropped{0}, malformed{0}, send_failures{0}, auth_failures{0},
        assets_requested{0}, assets_received{0};
  } counters;
  AssetRequests asset_requests{[this] { wakeup.notify(); }};
  std::unique_ptr<AssetDiskCache> asset_disk;
  std::unique_ptr<MeshCache> meshes;
  std::unique_ptr<VolumeCache> volumes;  // fetched as meshes are (ASSET_GET), SKYVOL1 files

 private:
  // --- sessions
  SessionEnd serve(zmq::socket_t& socket);
  std::optional<SessionEnd> handle(zmq::socket_t& socket, const api::Message& message);
  void send_ready(zmq::socket_t& socket);
  void abandon_units();
  bool wait_backoff(Ms delay);
  // --- units
  void accept_unit(const api::UnitMsg& unit);
  void forward_outcomes(zmq::socket_t& socket);
  void ask_for_assets(zmq::socket_t& socket);
  std::string fetch_asset(const std::string& id);
  // --- plumbing
  bool send(zmq::socket_t& socket, const api::Message& message);
  std::optional<api::Message> receive(zmq::socket_t& socket);
  api::HeartbeatMsg heartbeat() const;
  void log(const std::string& line) const;

  std::optional<zmq::socket_t> watch_handshakes(zmq::context_t& ctx, zmq::socket_t& socket);
  void read_monitor();

  zmq::socket_t* monitor_ = nullptr;  // handshake failures of the session's socket
  std::uint64_t monitor_count_ = 0;
  std::unique_ptr<RenderPool> pool_;
  std::uint64_t session_ = 0;                      // abandons renders of earlier sessions
  std::map<std::uint64_t, api::UnitRef> units_;  // attempt -> unit held in this session
  bool draining_ = false;
  bool heard_server_ = false;                     // this session got a message
  Clock::duration server_span_{};
  Clock::time_point server_expiry_{}, next_heartbeat_{};
};

FarmWorker::Impl::Impl(FarmWorkerOptions o) : options(std::move(o)) {
  threads = resolve_thread_count(options.threads);
  slots = options.slots > 0 ? std::min(options.slots, api::kMaxSlots) : std::min(threads + 1, api::kMaxSlots);
  if (options.id.empty()) options.id = default_worker_id();
  if (options.heartbeat_interval <= Ms(0)) options.heartbeat_interval = Ms(1000);
  options.heartbeat_liveness = std::max(1, options.heartbeat_liveness);
  if (options.reconnect_initial <= Ms(0)) options.reconnect_initial = Ms(1000);
  options.reconnect_max = std::max(options.reconnect_max, options.reconnect_initial);
  if (options.asset_timeout <= Ms(0)) options.asset_timeout = Ms(60000);
  if (!options.asset_cache_dir.empty())
    asset_disk = std::make_unique<AssetDiskCache>(options.asset_cache_dir, options.asset_cache_bytes);
  meshes = std::make_unique<MeshCache>(
      asset_disk.get(), [this](const std::string& id) { return fetch_asset(id); }, options.asset_memory_bytes);
  volumes = std::make_unique<VolumeCache>(
      asset_disk.get(), [this](const std::string& id) { return fetch_asset(id); }, options.asset_memory_bytes);
}

int FarmWorker::Impl::run() {
  if (running.exchange(true)) throw std::logic_error("FarmWorker::run called twice");
  pool_ = std::make_unique<RenderPool>(threads, static_cast<std::size_t>(options.setup_cache_jobs), meshes.get(),
                                       volumes.get(), wakeup);
  log("worker " + options.id + ": " + std::to_string(threads) + " render threads, " + std::to_string(slots) +
      " slots, server " + options.endpoint);
  zmq::context_t ctx(1);
  Ms backoff = options.reconnect_initial;
  int rc = 0;
  for (;;) {
    if (drain_requested()) break;  // not connected: nothing to hand back
    zmq::socket_t socket(ctx, zmq::socket_type::dealer);
    socket.set(zmq::sockopt::linger, 0);
    // The largest frame the server sends is an ASSET's mesh file.
    socket.set(zmq::sockopt::maxmsgsize,
               static_cast<std::int64_t>(std::max<std::size_t>(api::kMaxAssetBytes, std::size_t{64} << 20)));
    std::optional<zmq::socket_t> monitor;
    if (!options.server_key.empty()) {
      socket.set(zmq::sockopt::curve_serverkey, options.server_key);
      socket.set(zmq::sockopt::curve_publickey, options.public_key);
      socket.set(zmq::sockopt::curve_secretkey, options.secret_key);
      monitor = watch_handshakes(ctx, socket);
    }
    monitor_ = monitor ? &*monitor : nullptr;
    socket.connect(options.endpoint);
    const SessionEnd end = serve(socket);
    if (end == SessionEnd::kDrained && heard_server_)  // let the results and DISCONNECT leave
      socket.set(zmq::sockopt::linger, static_cast<int>(options.drain_linger.count()));
    socket.close();
    monitor_ = nullptr;
    if (end == SessionEnd::kDrained) break;
    if (end == SessionEnd::kRefused) {
      rc = 1;
      break;
    }
    abandon_units();
    if (heard_server_) backoff = options.reconnect_initial;
    if (!wait_backoff(backoff)) break;
    backoff = std::min(backoff * 2, options.reconnect_max);
  }
  stopping.store(true);
  asset_requests.close("the worker is stopping");  // render threads waiting for one finish now
  pool_->stop();
  return rc;  // ctx terminates here: queued results and DISCONNECT get drain_linger to leave
}

// Sleeps `delay` unless a drain is requested first (then false).
bool FarmWorker::Impl::wait_backoff(Ms delay) {
  log("worker " + options.id + ": server lost; reconnecting in " + std::to_string(delay.count()) + " ms");
  const auto until = Clock::now() + delay;
  while (!drain_requested()) {
    const auto left = std::chrono::duration_cast<Ms>(until - Clock::now());
    if (left <= Ms(0)) return true;
    zmq::pollitem_t item{nullptr, wakeup.read_fd(), ZMQ_POLLIN, 0};
    try {
      zmq::poll(&item, 1, std::min(left, kMaxTick));
    } catch (const zmq::error_t&) {  // EINTR
    }
    wakeup.drain();
    counters.results_dropped += pool_->take_outcomes().size();
  }
  return false;
}

// --- Sessions ---------------------------------------------------------------------------

SessionEnd FarmWorker::Impl::serve(zmq::socket_t& socket) {
  heard_server_ = false;
  draining_ = false;
  server_span_ = options.heartbeat_interval * options.heartbeat_liveness;
  send_ready(socket);
  asset_requests.resend_all();  // questions sent on an earlier socket are lost with it
  for (;;) {
    if (paused.load()) {
      std::this_thread::sleep_for(Ms(10));
      continue;
    }
    zmq::pollitem_t items[] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                               {nullptr, wakeup.read_fd(), ZMQ_POLLIN, 0},
                               {monitor_ ? monitor_->handle() : nullptr, -1, ZMQ_POLLIN, 0}};
    const auto to_heartbeat = std::chrono::duration_cast<Ms>(next_heartbeat_ - Clock::now());
    try {
      zmq::poll(items, monitor_ ? 3 : 2, std::clamp(to_heartbeat, Ms(0), kMaxTick));
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) throw;
    }
    if (items[1].revents & ZMQ_POLLIN) wakeup.drain();
    if (monitor_ && (items[2].revents & ZMQ_POLLIN)) read_monitor();
    for (int i = 0; i < 1000; ++i) {  // bounded: heartbeats must go out whatever arrives
      const std::optional<api::Message> message = receive(socket);
      if (!message) break;
      if (const auto end = handle(socket, *message)) return *end;
    }
    // A drain is announced before any result goes out: a result returns a
    // credit, and the server must not spend it on a new unit for us.
    if (drain_requested() && !draining_) {
      draining_ = true;
      log("worker " + options.id + ": draining (" + std::to_string(units_.size()) + " units to finish)");
      send(socket, heartbeat());
    }
    ask_for_assets(socket);
    forward_outcomes(socket);
    if (draining_ && units_.empty()) {
      send(socket, api::DisconnectMsg{"worker draining", false});
      return SessionEnd::kDrained;
    }
    const auto now = Clock::now();
    if (now >= next_heartbeat_) {
      send(socket, heartbeat());
      next_heartbeat_ = now + options.heartbeat_interval;
    }
    if (now > server_expiry_) return SessionEnd::kServerGone;
  }
}

std::optional<SessionEnd> FarmWorker::Impl::handle(zmq::socket_t& socket, const api::Message& message) {
  if (const auto* hb = std::get_if<api::HeartbeatMsg>(&message)) {
    if (hb->heartbeat_ms > 0)
      server_span_ = std::max(options.heartbeat_interval, Ms(hb->heartbeat_ms)) * options.heartbeat_liveness;
    server_expiry_ = Clock::now() + server_span_;
  } else if (const auto* unit = std::get_if<api::UnitMsg>(&message)) {
    accept_unit(*unit);
  } else if (const auto* cancel = std::get_if<api::CancelMsg>(&message)) {
    ++counters.cancels_received;
    if (units_.erase(cancel->attempt)) pool_->remove(session_, cancel->attempt);
  } else if (const auto* bye = std::get_if<api::DisconnectMsg>(&message)) {
    log("worker " + options.id + ": server disconnected" + (bye->reason.empty() ? "" : ": " + bye->reason));
    return bye->fatal ? SessionEnd::kRefused : SessionEnd::kServerGone;
  } else if (const auto* asset = std::get_if<api::AssetMsg>(&message)) {
    if (asset_requests.answer(*asset) && asset->ok) ++counters.assets_received;
  } else if (std::holds_alternative<api::ReregisterMsg>(message)) {
    abandon_units();
    if (draining_) return SessionEnd::kDrained;  // the server holds nothing of ours
    send_ready(socket);
    asset_requests.resend_all();  // an unregistered worker's questions were not answered
  } else {
    ++counters.malformed;  // READY, RESULT, FAILED: not for a worker
  }
  return std::nullopt;
}

void FarmWorker::Impl::send_ready(zmq::socket_t& socket) {
  api::ReadyMsg ready;
  ready.id = options.id;
  ready.cores = threads;
  ready.slots = slots;
  ready.capabilities = {{"spectral", true}, {"methods", {"path"}}, {"probe", api::kProbeUnitsVersion}};
  ready.heartbeat_ms = static_cast<int>(options.heartbeat_interval.count());
  // Units queue in the render pool anyway: with the default slots the server
  // may send a few more when units are short (api/wire.h "prefetch"); slots
  // set by hand (--slots) are the most it ever holds.
  if (options.slots <= 0) ready.prefetch = std::min(api::kMaxSlots, 8 * slots);
  if (!options.token.empty()) ready.token = options.token;
  ++counters.sessions;
  send(socket, ready);
  const auto now = Clock::now();
  server_expiry_ = now + server_span_;
  next_heartbeat_ = now + options.heartbeat_interval;
}

// A PAIR socket receiving the socket's handshake failures (its own inproc
// endpoint per session, so an old session's events never mix in).
std::optional<zmq::socket_t> FarmWorker::Impl::watch_handshakes(zmq::context_t& ctx, zmq::socket_t& socket) {
  const std::string endpoint = "inproc://skyfarm-worker-monitor-" + std::to_string(++monitor_count_);
  if (zmq_socket_monitor(socket.handle(), endpoint.c_str(),
                         ZMQ_EVENT_HANDSHAKE_FAILED_AUTH | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                             ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL) != 0)
    return std::nullopt;
  zmq::socket_t monitor(ctx, zmq::socket_type::pair);
  monitor.set(zmq::sockopt::linger, 0);
  monitor.connect(endpoint);
  return monitor;
}

void FarmWorker::Impl::read_monitor() {
  for (;;) {
    std::vector<zmq::message_t> event;
    if (!zmq::recv_multipart(*monitor_, std::back_inserter(event), zmq::recv_flags::dontwait)) return;
    if (event.empty() || event[0].size() < 6) continue;
    std::uint16_t id = 0;
    std::memcpy(&id, event[0].data(), sizeof id);
    const auto n = ++counters.auth_failures;
    if (n > 3 && (n & (n - 1)) != 0) continue;  // the first ones, then every power of two
    log("worker " + options.id + ": the server refused the CURVE handshake (" +
        (id == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH ? std::string("our key is not allowed")
                                               : std::string("wrong server key or mechanism")) +
        "; check --secret-file / --key-file / --server-key; " + std::to_string(n) + " so far)");
  }
}

// The server requeues what we held: forget it (renders in progress finish unseen).
void FarmWorker::Impl::abandon_units() {
  ++session_;
  units_.clear();
  pool_->clear_queue();
}

// --- Units -------------------------------------------------------------------------------

void FarmWorker::Impl::accept_unit(const api::UnitMsg& unit) {
  ++counters.units_received;
  if (!units_.emplace(unit.unit.attempt, unit.unit).second) return;  // a duplicate dispatch
  pool_->push(RenderTask{session_, unit});
}

void FarmWorker::Impl::forward_outcomes(zmq::socket_t& socket) {
  for (RenderOutcome& o : pool_->take_outcomes()) {
    if (o.session != session_ || units_.erase(o.attempt) == 0) {
      ++counters.results_dropped;  // cancelled, or from an abandoned session
      continue;
    }
    const bool ok = std::holds_alternative<api::ResultMsg>(o.message);
    if (!ok) log("worker " + options.id + ": unit failed: " + std::get<api::FailedMsg>(o.message).message);
    if (send(socket, o.message)) ++(ok ? counters.results_sent : counters.failures_sent);
  }
}

// --- Assets ------------------------------------------------------------------------------

void FarmWorker::Impl::ask_for_assets(zmq::socket_t& socket) {
  for (const std::string& id : asset_requests.take_unsent()) {
    if (send(socket, api::AssetGetMsg{id})) {
      ++counters.assets_requested;
      log("worker " + options.id + ": fetching asset " + id);
    } else {
      asset_requests.unsent(id);
    }
  }
}

// On a render thread (MeshCache): once more when no answer came.
std::string FarmWorker::Impl::fetch_asset(const std::string& id) {
  try {
    return asset_requests.fetch(id, options.asset_timeout);
  } catch (const AssetUnavailable& e) {
    if (stopping.load()) throw;
    log("worker " + options.id + ": " + e.what() + "; asking again");
    return asset_requests.fetch(id, options.asset_timeout);
  }
}

// --- Plumbing ------------------------------------------------------------------------------

bool FarmWorker::Impl::send(zmq::socket_t& socket, const api::Message& message) {
  const api::Frames frames = api::encode(message);
  try {
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const auto more = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
      if (!socket.send(zmq::buffer(frames[i]), more | zmq::send_flags::dontwait)) {
        ++counters.send_failures;  // EAGAIN on the first frame: the queue is full
        return false;
      }
    }
    return true;
  } catch (const zmq::error_t& e) {
    ++counters.send_failures;
    log(std::string("worker: send failed: ") + e.what());
    return false;
  }
}

// The next message from the server, nullopt when none is waiting; a
// malformed one is counted and skipped (it still proves the server alive).
std::optional<api::Message> FarmWorker::Impl::receive(zmq::socket_t& socket) {
  for (;;) {
    std::vector<zmq::message_t> parts;
    try {
      if (!zmq::recv_multipart(socket, std::back_inserter(parts), zmq::recv_flags::dontwait)) return std::nullopt;
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;
      throw;
    }
    heard_server_ = true;
    server_expiry_ = Clock::now() + server_span_;
    api::Frames frames;
    for (auto& p : parts) frames.push_back(p.to_string());
    std::string error;
    if (auto message = api::try_decode(frames, &error)) return message;
    ++counters.malformed;
    log("worker " + options.id + ": dropped a malformed message from the server: " + error);
  }
}

api::HeartbeatMsg FarmWorker::Impl::heartbeat() const {
  return api::HeartbeatMsg{static_cast<int>(options.heartbeat_interval.count()), draining_};
}

void FarmWorker::Impl::log(const std::string& line) const {
  if (options.log) options.log(line);
  else std::cerr << "skyfarm-worker: " << line << "\n";
}

// --- FarmWorker -------------------------------------------------------------------------

FarmWorker::FarmWorker(FarmWorkerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
FarmWorker::~FarmWorker() = default;

int FarmWorker::run() { return impl_->run(); }

void FarmWorker::request_drain() {
  impl_->drain.store(true);
  impl_->wakeup.notify();
}

const std::string& FarmWorker::id() const { return impl_->options.id; }
int FarmWorker::threads() const { return impl_->threads; }
int FarmWorker::slots() const { return impl_->slots; }

FarmWorkerStats FarmWorker::stats() const {
  const auto& c = impl_->counters;
  return FarmWorkerStats{c.sessions.load(),         c.units_received.load(),  c.results_sent.load(),
                         c.failures_sent.load(),    c.cancels_received.load(), c.results_dropped.load(),
                         c.malformed.load(),        c.send_failures.load(),     c.auth_failures.load(),
                         c.assets_requested.load(), c.assets_received.load()};
}

void FarmWorker::set_paused_for_testing(bool paused) {
  impl_->paused.store(paused);
  impl_->wakeup.notify();
}

std::string default_worker_id() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') std::snprintf(host, sizeof host, "worker");
  std::random_device rd;
  char suffix[16];
  std::snprintf(suffix, sizeof suffix, "%04x", static_cast<unsigned>(rd() & 0xffffu));
  return std::string(host) + "-" + std::to_string(::getpid()) + "-" + suffix;
}

}  // namespace skyfarm

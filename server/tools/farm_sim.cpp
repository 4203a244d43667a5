#include "server/tools/farm_sim.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <queue>
#include <stdexcept>

#include <zmq_addon.hpp>

#include "api/curve_keys.h"
#include "api/render_request.h"
#include "api/render_spec.h"
#include "api/wire.h"
#include "common/film/film_tile.h"
#include "common/render/render_plan.h"
#include "common/sun/sun.h"
#include "server/jobs/job_service.h"
#include "server/probes/probe_router.h"
#include "server/probes/probe_service.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using SimClock = std::chrono::steady_clock;
using Ms = std::chrono::milliseconds;

constexpr int kHeartbeatMs = 1000;

// A field of /proc/self/status ("VmRSS", "VmHWM") in MiB; 0 where unknown.
double status_mb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::strtod(line.c_str() + field.size() + 1, nullptr) / 1024.0;
  return 0.0;
}

double ms_between(SimClock::time_point a, SimClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

nlohmann::json request_body(const FarmSimOptions& o, int passes, int seed) {
  return {{"sun", {{"zenith_deg", 40}, {"azimuth_deg", 120}}},
          {"camera", {{"projection", "equirectangular"}, {"width", o.width}, {"height", o.height}}},
          {"spectral", {{"batches", o.batches}}},
          {"quality", {{"samples_per_pixel", RenderPlan{}.samples_per_pass * passes}}},
          {"output", {{"half", false}}},
          {"seed", seed}};
}

RenderPlan plan_of(const api::RenderRequest& r) {
  return api::render_plan_for(r, Sun::from_spec(r.sun, r.location, r.time));
}

api::Frames frames_of(std::vector<zmq::message_t>& parts) {
  api::Frames frames;
  frames.reserve(parts.size());
  for (auto& p : parts) frames.push_back(p.to_string());
  return frames;
}

bool send_frames(zmq::socket_t& socket, const api::Frames& frames) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto more = i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
    if (!socket.send(zmq::buffer(frames[i]), more | zmq::send_flags::dontwait)) return false;
  }
  return true;
}

struct SimWorker {
  zmq::socket_t socket;
  std::string id;
  bool joined = false;
  std::deque<SimClock::time_point> credit_free;  // when each free slot came free
  SimClock::time_point busy_until{};             // its one core renders until then
};

struct PendingResult {
  SimClock::time_point due;
  std::size_t worker = 0;
  api::Frames frames;
  bool operator>(const PendingResult& o) const { return due > o.due; }
};

// Room for every simulated worker's socket (ZeroMQ's default is 1023).
zmq::context_t make_context(int sockets) {
  zmq::context_t ctx(1);
  ctx.set(zmq::ctxopt::max_sockets, std::max(1024, sockets + 16));
  return ctx;
}

// The simulated workers: one thread, every socket in one zmq_poll.
class SimWorkers {
 public:
  SimWorkers(const FarmSimOptions& options, const std::string& endpoint) : options_(options) {
    workers_.reserve(static_cast<std::size_t>(options.workers));
    for (int i = 0; i < options.workers; ++i) {
      SimWorker w{zmq::socket_t(ctx_, zmq::socket_type::dealer), "sim-" + std::to_string(i), false, {}, {}};
      configure_sim_worker_socket(w.socket, options.curve);
      w.socket.connect(endpoint);
      workers_.push_back(std::move(w));
    }
    items_.resize(workers_.size());
    for (std::size_t i = 0; i < workers_.size(); ++i)
      items_[i] = zmq::pollitem_t{workers_[i].socket.handle(), 0, ZMQ_POLLIN, 0};
    for (std::size_t i = 0; i < workers_.size(); ++i) send_ready(i);
    next_heartbeat_ = SimClock::now() + Ms(kHeartbeatMs);
  }
  ~SimWorkers() {
    for (auto& w : workers_) w.socket.close();
  }

  // One round: waits up to `wait` for messages, answers them, sends what is due.
  void step(Ms wait) {
    const auto now = SimClock::now();
    if (!pending_.empty()) wait = std::clamp(std::chrono::duration_cast<Ms>(pending_.top().due - now), Ms(0), wait);
    zmq::poll(items_.data(), items_.size(), wait);
    for (std::size_t i = 0; i < items_.size(); ++i)
      if (items_[i].revents & ZMQ_POLLIN) receive(i);
    const auto after = SimClock::now();
    while (!pending_.empty() && pending_.top().due <= after) {
      PendingResult p = pending_.top();
      pending_.pop();
      send_result(p.worker, p.frames);
    }
    if (after >= next_heartbeat_) {
      const api::Frames hb = api::encode(api::HeartbeatMsg{kHeartbeatMs, false});
      for (auto& w : workers_) send_frames(w.socket, hb);
      next_heartbeat_ = after + Ms(kHeartbeatMs);
    }
  }

  bool all_joined() const {
    return std::all_of(workers_.begin(), workers_.end(), [](const SimWorker& w) { return w.joined; });
  }
  std::vector<double>& latencies_ms() { return latencies_ms_; }
  std::int64_t results_sent() const { return results_sent_; }
  // Credit waits counted from here on (the submission): before it no work existed.
  void reset_credit_clock(SimClock::time_point t) {
    for (auto& w : workers_)
      for (auto& c : w.credit_free) c = t;
  }

 private:
  void send_ready(std::size_t i) {
    SimWorker& w = workers_[i];
    api::ReadyMsg ready;
    ready.id = w.id;
    ready.cores = 1;
    ready.slots = options_.slots;
    ready.prefetch = options_.prefetch;
    ready.heartbeat_ms = kHeartbeatMs;
    send_frames(w.socket, api::encode(ready));
    w.credit_free.assign(static_cast<std::size_t>(options_.slots), SimClock::now());
  }

  void receive(std::size_t i) {
    SimWorker& w = workers_[i];
    for (;;) {
      std::vector<zmq::message_t> parts;
      if (!zmq::recv_multipart(w.socket, std::back_inserter(parts), zmq::recv_flags::dontwait)) return;
      const std::optional<api::Message> m = api::try_decode(frames_of(parts));
      if (!m) continue;
      if (std::holds_alternative<api::HeartbeatMsg>(*m)) {
        w.joined = true;
      } else if (const auto* unit = std::get_if<api::UnitMsg>(&*m)) {
        on_unit(i, *unit);
      } else if (std::holds_alternative<api::CancelMsg>(*m)) {
        w.credit_free.push_back(SimClock::now());
      } else if (std::holds_alternative<api::ReregisterMsg>(*m)) {
        send_ready(i);
      }
    }
  }

  void on_unit(std::size_t i, const api::UnitMsg& unit) {
    SimWorker& w = workers_[i];
    const auto now = SimClock::now();
    if (!w.credit_free.empty()) {
      latencies_ms_.push_back(ms_between(w.credit_free.front(), now));
      w.credit_free.pop_front();
    }
    const RenderPlan& plan = plan_for(unit.unit.job, unit.request);
    const std::string& tile = result_tile(plan, unit);
    std::uint64_t paths = 0;
    api::Frames frames = api::encode(api::ResultMsg{unit.unit, paths, options_.unit_ms / 1000.0, tile});
    if (options_.unit_ms <= 0.0) {
      send_result(i, frames);
    } else {
      // One core: units render one after the other, in arrival order.
      const auto due = std::max(now, w.busy_until) + std::chrono::duration_cast<SimClock::duration>(
                                                         std::chrono::duration<double, std::milli>(options_.unit_ms));
      w.busy_until = due;
      pending_.push(PendingResult{due, i, std::move(frames)});
    }
  }

  void send_result(std::size_t i, const api::Frames& frames) {
    SimWorker& w = workers_[i];
    if (send_frames(w.socket, frames)) ++results_sent_;
    w.credit_free.push_back(SimClock::now());
  }

  const RenderPlan& plan_for(const std::string& job, const std::string& request_text) {
    auto it = plans_.find(job);
    if (it == plans_.end()) it = plans_.emplace(job, plan_of(api::parse_render_request(request_text))).first;
    return it->second;
  }

  // The unit's result: its tile, its batch holding each pixel's sample count.
  const std::string& result_tile(const RenderPlan& plan, const api::UnitMsg& unit) {
    int x0 = 0, y0 = 0, width = 0, height = 0;
    plan.tile_rect(unit.unit.tile, &x0, &y0, &width, &height);
    WorkUnit u{unit.unit.tile, unit.unit.batch, unit.unit.pass, {}};
    for (const auto& [even, odd] : unit.samples_per_pass) u.samples.push_back({even, odd});
    std::string key = unit.unit.job + "/" + std::to_string(u.tile) + "/" + std::to_string(u.batch) + ":";
    std::vector<int> counts;
    counts.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    for (int y = y0; y < y0 + height; ++y)
      for (int x = x0; x < x0 + width; ++x) {
        int first = 0, end = 0;
        plan.sample_range(u, x, y, &first, &end);
        counts.push_back(end - first);
      }
    key.append(reinterpret_cast<const char*>(counts.data()), counts.size() * sizeof(int));
    auto it = tiles_.find(key);
    if (it != tiles_.end()) return it->second;
    FilmTile film(x0, y0, width, height, plan.batches);
    std::size_t k = 0;
    for (int y = y0; y < y0 + height; ++y)
      for (int x = x0; x < x0 + width; ++x) {
        const double n = counts[k++];
        // Every sample (X, Y, Z) = (1, 1, 1) and L = 1: plausible, finite sums.
        film.set_sums(x, y, u.batch, PixelBatchSums{n, n, n, n, n, n, n, n, n});
      }
    const std::vector<std::uint8_t> bytes = film.serialize();
    return tiles_.emplace(std::move(key), std::string(bytes.begin(), bytes.end())).first->second;
  }

  const FarmSimOptions& options_;
  zmq::context_t ctx_ = make_context(options_.workers);
  std::vector<SimWorker> workers_;
  std::vector<zmq::pollitem_t> items_;
  std::priority_queue<PendingResult, std::vector<PendingResult>, std::greater<>> pending_;
  std::map<std::string, RenderPlan> plans_;
  std::map<std::string, std::string> tiles_;
  std::vector<double> latencies_ms_;
  std::int64_t results_sent_ = 0;
  SimClock::time_point next_heartbeat_{};
};

double percentile(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::min<double>(static_cast<double>(v.size() - 1), q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// A fresh temporary directory, removed with this object.
struct TempDir {
  fs::path path;
  bool owned = false;
  explicit TempDir(const fs::path& given) {
    if (!given.empty()) {
      path = given;
      return;
    }
    std::string tmpl = (fs::temp_directory_path() / "skyfarm-farm-sim-XXXXXX").string();
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary directory in " + fs::temp_directory_path().string());
    path = tmpl;
    owned = true;
  }
  ~TempDir() {
    std::error_code ec;
    if (owned) fs::remove_all(path, ec);
  }
};

}  // namespace

namespace {
// Not a credential anywhere: the broker of the simulation lets in its keys only.
constexpr const char* kSimSecret = "skyfarm-farm-bench simulation secret";
}  // namespace

void configure_sim_worker_socket(zmq::socket_t& socket, bool curve) {
  socket.set(zmq::sockopt::linger, 0);
  socket.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(64) << 20);
  if (!curve) return;
  static const api::CurveKeyPair worker = api::derive_worker_keys(kSimSecret);
  static const api::CurveKeyPair server = api::derive_server_keys(kSimSecret);
  socket.set(zmq::sockopt::curve_serverkey, server.public_key);
  socket.set(zmq::sockopt::curve_publickey, worker.public_key);
  socket.set(zmq::sockopt::curve_secretkey, worker.secret_key);
}

FarmSimResult run_farm_sim(const FarmSimOptions& o) {
  if (o.workers < 1) throw std::runtime_error("--workers must be at least 1");
  if (o.jobs < 1) throw std::runtime_error("--jobs must be at least 1");
  if (o.units < o.jobs) throw std::runtime_error("--units must be at least --jobs");
  if (o.slots < 1 || o.slots > api::kMaxSlots)
    throw std::runtime_error("--slots must be in [1, " + std::to_string(api::kMaxSlots) + "]");
  if (o.prefetch < 0 || o.prefetch > api::kMaxSlots)
    throw std::runtime_error("--prefetch must be in [0, " + std::to_string(api::kMaxSlots) + "]");
  if (o.unit_ms < 0.0) throw std::runtime_error("--unit-ms must not be negative");

  // The requests: each job's share of the units, in whole passes.
  std::vector<api::RenderRequest> requests;
  std::int64_t expected = 0;
  for (int j = 0; j < o.jobs; ++j) {
    const std::int64_t share = o.units / o.jobs + (j < o.units % o.jobs ? 1 : 0);
    api::RenderRequest one_pass;
    try {
      one_pass = api::parse_render_request(request_body(o, 1, j + 1));
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("the simulated request is invalid: ") + e.what());
    }
    const RenderPlan p1 = plan_of(one_pass);
    const std::int64_t per_pass = static_cast<std::int64_t>(p1.tile_count()) * p1.batches;
    const auto passes = static_cast<int>((share + per_pass - 1) / per_pass);
    try {
      requests.push_back(api::parse_render_request(request_body(o, passes, j + 1)));
    } catch (const std::exception& e) {
      throw std::runtime_error("--units: " + std::to_string(share) + " units per job need " + std::to_string(passes) +
                               " passes of " + std::to_string(per_pass) + " units, too many for one request: " + e.what());
    }
    expected += plan_of(requests.back()).unit_count();
  }

  const TempDir dir(o.data_dir);
  ServiceLimits limits;
  limits.max_active_jobs = std::max(limits.max_active_jobs, o.jobs);
  limits.max_queue_units = std::max<int>(limits.max_queue_units, static_cast<int>(std::min<std::int64_t>(expected, 1 << 30)));
  JobService service(dir.path, limits);
  std::atomic<int> finished{0};
  service.set_state_observer([&](const std::string&, JobState state) {
    if (is_terminal(state)) ++finished;
  });
  ProbeLimits probe_limits;
  probe_limits.unit_timeout_s = std::min(limits.unit_timeout_s, kProbeUnitTimeoutCapS);
  ProbeService probes(probe_limits);
  ProbeRouter router(probes, service);
  BrokerOptions broker_options;
  broker_options.endpoint = "tcp://127.0.0.1:*";
  broker_options.log = o.log ? o.log : [](std::string_view) {};
  if (o.curve) {
    broker_options.curve_secret_key = api::derive_server_keys(kSimSecret).secret_key;
    broker_options.auth.allowed_keys = {api::derive_worker_keys(kSimSecret).public_key};
  }
  Broker broker(router, broker_options);
  broker.start();

  FarmSimResult result;
  result.units_expected = expected;
  {
    SimWorkers workers(o, broker.bound_endpoint());
    const auto deadline = SimClock::now() + std::chrono::duration_cast<SimClock::duration>(
                                                std::chrono::duration<double>(o.timeout_s));
    while (!workers.all_joined() && SimClock::now() < deadline) workers.step(Ms(10));

    result.rss_start_mb = status_mb("VmRSS");
    result.rss_peak_mb = result.rss_start_mb;
    std::vector<std::string> ids;
    const auto t0 = SimClock::now();
    for (const auto& r : requests) ids.push_back(service.submit(r, std::nullopt).id);
    broker.wake();
    workers.reset_credit_clock(t0);
    auto next_sample = t0;
    while (finished.load() < o.jobs && SimClock::now() < deadline) {
      workers.step(Ms(5));
      if (const auto now = SimClock::now(); now >= next_sample) {
        result.rss_peak_mb = std::max(result.rss_peak_mb, status_mb("VmRSS"));
        next_sample = now + Ms(100);
      }
    }
    const auto t1 = SimClock::now();
    result.rss_end_mb = status_mb("VmRSS");
    result.rss_peak_mb = std::max(result.rss_peak_mb, result.rss_end_mb);
    result.seconds = std::chrono::duration<double>(t1 - t0).count();
    auto& lat = workers.latencies_ms();
    result.latency_p50_ms = percentile(lat, 0.50);
    result.latency_p99_ms = percentile(lat, 0.99);
    result.latency_max_ms = lat.empty() ? 0.0 : *std::max_element(lat.begin(), lat.end());
    result.results_sent = workers.results_sent();

    result.all_done = true;
    for (const auto& id : ids) {
      const nlohmann::json s = service.status(id).value_or(nlohmann::json::object());
      FarmSimJob job{id, s.value("state", ""), 0, 0};
      if (s.contains("progress")) {
        job.units_done = s["progress"].value("units_done", std::int64_t{0});
        job.units_total = s["progress"].value("units_total", std::int64_t{0});
      }
      result.all_done = result.all_done && job.state == "done" && job.units_done == job.units_total;
      result.units_merged += job.units_done;
      result.jobs.push_back(std::move(job));
    }
    result.units_per_second = result.seconds > 0.0 ? static_cast<double>(result.units_merged) / result.seconds : 0.0;
    broker.stop();
    result.broker = broker.stats();
  }
  service.set_state_observer({});
  return result;
}

}  // namespace skyfarm::server

// Test support: workers for a ProbeService (server/probes/probe_service.h) in the
// test process, driving its BrokerBackend side as the broker would: each
// asks for units, traces them with worker/probe_unit.h (exactly what a
// skyfarm-worker does) and hands the result back, or misbehaves as told.
#pragma once
#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "server/probes/probe_service.h"
#include "worker/probe_unit.h"

namespace skyfarm::testing {

// Polls `pred` every 2 ms until it holds (true) or `timeout` passes (false).
template <class Pred>
bool eventually_true(Pred pred, std::chrono::milliseconds timeout = std::chrono::milliseconds(10000)) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

inline nlohmann::json worker_info(const std::string& id, bool runs_probes = true) {
  nlohmann::json caps = {{"spectral", true}};
  if (runs_probes) caps["probe"] = api::kProbeUnitsVersion;
  return {{"id", id}, {"cores", 1}, {"slots", 2}, {"version", api::kProtocolVersion}, {"capabilities", caps}};
}

enum class ProbeWorkerMode {
  kTrace,    // trace every unit and return it
  kFail,     // answer every unit with unit_failed("boom from <id>")
  kCorrupt,  // return bytes that are not a ProbeUnitSums
  kHold,     // take units and never answer
};

class ProbeWorker {
 public:
  ProbeWorker(server::ProbeService& service, std::string id, ProbeWorkerMode mode = ProbeWorkerMode::kTrace)
      : service_(service), id_(std::move(id)), mode_(mode) {
    service_.worker_joined(id_, worker_info(id_));
    thread_ = std::thread([this] { loop(); });
  }
  ~ProbeWorker() { stop(); }
  ProbeWorker(const ProbeWorker&) = delete;
  ProbeWorker& operator=(const ProbeWorker&) = delete;

  // Stops asking; `leave`: the broker declares it lost (worker_left).
  void stop(bool leave = false) {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (leave) service_.worker_left(id_);
  }
  int units() const { return units_.load(); }
  const std::string& id() const { return id_; }

 private:
  void loop() {
    while (!stop_) {
      const std::optional<server::UnitAssignment> unit = service_.next_unit(id_);
      if (!unit) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      ++units_;
      answer(*unit);
    }
  }

  void answer(const server::UnitAssignment& a) {
    const api::UnitMsg msg{{a.key.job_id, a.key.tile, a.key.batch, a.key.pass, a.attempt}, a.request_canonical, a.kind};
    switch (mode_) {
      case ProbeWorkerMode::kHold: return;
      case ProbeWorkerMode::kFail: service_.unit_failed(id_, a.key, a.attempt, "boom from " + id_); return;
      case ProbeWorkerMode::kCorrupt: service_.unit_done(id_, a.key, a.attempt, {1, 2, 3}, 0); return;
      case ProbeWorkerMode::kTrace: break;
    }
    const api::Message m = run_probe_unit(make_probe_setup(a.request_canonical), msg);
    if (const auto* r = std::get_if<api::ResultMsg>(&m))
      service_.unit_done(id_, a.key, a.attempt, api::payload_bytes(r->film_tile), r->paths);
    else
      service_.unit_failed(id_, a.key, a.attempt, std::get<api::FailedMsg>(m).message);
  }

  server::ProbeService& service_;
  std::string id_;
  ProbeWorkerMode mode_;
  std::atomic<bool> stop_{false};
  std::atomic<int> units_{0};
  std::thread thread_;
};

}  // namespace skyfarm::testing

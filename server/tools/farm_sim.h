// A render farm in one process, for measuring the scheduler at scale: the
// real JobService (behind the ProbeRouter, as skyfarm-server runs it) and
// the real Broker, driven by simulated workers that render nothing.
//
// Parameters (FarmSimOptions)
//   workers      simulated workers: ZeroMQ DEALER sockets served by the
//                calling thread (zmq_poll over all of them), each speaking
//                api/wire.h (READY, HEARTBEAT, RESULT) with `slots` credit
//                and `prefetch` (the units it accepts beyond them)
//   units        units of work in all, shared out over `jobs` jobs (each job
//                a request of width x height pixels, `batches` wavelength
//                batches and as many 16-sample passes as its share needs,
//                rounded up, so the figure reported is the plans' own count)
//   unit_ms      how long a simulated worker "renders" a unit before it
//                answers, one unit at a time (one core; the others it holds
//                wait), 0: at once, the scheduler alone is measured
//   data_dir     the server's data directory (empty: a fresh temporary one,
//                removed afterwards)
//   timeout_s    gives up (all_done false) after this long
//
// A result is a valid FilmTile of the unit's geometry and batch count whose
// pixels hold the samples the unit asked for (RenderPlan::sample_range), with
// made-up sums; one is built per distinct (job, tile, batch, counts) and
// reused, so the workers cost little beside the server.
//
// Measured (FarmSimResult): units merged per second from the submission to
// the last job done (or the timeout); the dispatch latency, from a worker's credit coming
// free (READY, or a RESULT sent) to the next UNIT it receives, p50 and p99;
// and the process's memory: VmRSS when the jobs are submitted, its peak
// during the run (sampled), and at the end.  The simulated workers live in
// the same process, so the RSS figures include them (their share is the
// baseline: sockets, made before the submission).
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <zmq.hpp>

#include "server/broker/broker.h"

namespace skyfarm::server {

struct FarmSimOptions {
  int workers = 1000;
  std::int64_t units = 100000;
  int jobs = 1;
  int slots = 2;
  int prefetch = 16;  // READY "prefetch", as skyfarm-worker announces it (8 x slots)
  double unit_ms = 0.0;
  int width = 1, height = 1, batches = 64;
  std::filesystem::path data_dir;
  double timeout_s = 600.0;
  // CurveZMQ between the broker and the simulated workers, as skyfarm-server
  // runs it (keys derived from a fixed secret); false: the NULL mechanism.
  bool curve = true;
  // Broker log lines; empty: dropped.
  std::function<void(std::string_view)> log;
};

struct FarmSimJob {
  std::string id;
  std::string state;
  std::int64_t units_done = 0, units_total = 0;
};

struct FarmSimResult {
  bool all_done = false;             // every job ended "done" with all its units merged
  std::int64_t units_expected = 0;   // the plans' unit count over all jobs
  std::int64_t units_merged = 0;     // over all jobs, when the run ended
  std::int64_t results_sent = 0;     // RESULT messages of the simulated workers
  double seconds = 0.0;              // submission -> last job done (or the timeout)
  double units_per_second = 0.0;     // units_merged / seconds
  double latency_p50_ms = 0.0, latency_p99_ms = 0.0, latency_max_ms = 0.0;
  double rss_start_mb = 0.0, rss_peak_mb = 0.0, rss_end_mb = 0.0;
  std::vector<FarmSimJob> jobs;
  BrokerStats broker;
};

// Sets up one simulated worker's DEALER socket before it connects (linger,
// message size, and with `curve` the CURVE client keys of the simulation's
// shared secret).
void configure_sim_worker_socket(zmq::socket_t& socket, bool curve);

// Runs the simulation to completion (or timeout_s); throws std::runtime_error
// when the farm cannot be set up (bad options, no data directory).
FarmSimResult run_farm_sim(const FarmSimOptions& options);

}  // namespace skyfarm::server

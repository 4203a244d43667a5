// skyfarm-sky-sweep: the sky cache's cold time sweep (scripts/bench-sky.sh):
// 24 sun positions of one day at one place (Ithaca, 2013-05-27, every hour
// at half past), each the table GET /v1/sky builds for it (parse_sky_query
// with the server's defaults), asked one after the other of a fresh
// SkyService, once making every table in full (the cache before it reused
// atmosphere tables) and once with reuse (LutSky::with_sun after the first).
//
//   skyfarm-sky-sweep [--repeat 3] [--positions 24]
//
// Output: one key=value line per mode with the medians over the repeats of
// the sweep's wall time and of its CPU time (the tables are built on the
// calling thread, so CPU time is what a shared machine does not inflate),
// per sweep and per table, then the ratios.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "server/sky/http_sky.h"
#include "server/sky/sky_service.h"

namespace {

using skyfarm::server::QueryParams;
using skyfarm::server::SkyService;
using skyfarm::server::SkyServiceOptions;

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Times {
  double wall = 0.0, cpu = 0.0;
};

// The tables of a sweep, cold.
Times sweep(bool reuse, int positions) {
  SkyServiceOptions options;
  options.reuse_atmosphere_tables = reuse;
  SkyService service(options);
  const auto start = std::chrono::steady_clock::now();
  const double cpu0 = thread_cpu_seconds();
  for (int i = 0; i < positions; ++i) {
    char time[64];
    std::snprintf(time, sizeof time, "2013-05-27T%02d:30:00-04:00", i % 24);
    const QueryParams params = {{"lat", "42.44"},  {"lon", "-76.48"},   {"time", time},
                                {"view_zenith", "35"}, {"view_azimuth", "250"}};
    const auto q = skyfarm::server::parse_sky_query(params, skyfarm::server::SkyRoute::kLookup,
                                                    service.options().resolution.spectral_bins);
    service.table(q.table);
  }
  Times t;
  t.cpu = thread_cpu_seconds() - cpu0;
  t.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (service.stats().table_builds != static_cast<std::uint64_t>(positions)) std::cerr << "unexpected cache hits\n";
  return t;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3, positions = 24;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else if (a == "--positions" && i + 1 < argc) positions = std::clamp(std::atoi(argv[++i]), 1, 24);
    else {
      std::cerr << "usage: skyfarm-sky-sweep [--repeat N] [--positions 1..24]\n";
      return 2;
    }
  }
  Times full, reused;
  for (const bool reuse : {false, true}) {
    std::vector<double> walls, cpus;
    for (int r = 0; r < repeat; ++r) {
      const Times t = sweep(reuse, positions);
      walls.push_back(t.wall);
      cpus.push_back(t.cpu);
    }
    const Times m{median(walls), median(cpus)};
    (reuse ? reused : full) = m;
    std::printf("sweep=%s positions=%d wall_ms=%.1f cpu_ms=%.1f cpu_ms_per_table=%.1f repeats=%d\n",
                reuse ? "with_sun" : "full_builds", positions, 1e3 * m.wall, 1e3 * m.cpu, 1e3 * m.cpu / positions,
                repeat);
  }
  std::printf("sweep_speedup_wall=%.2f sweep_speedup_cpu=%.2f\n", full.wall / reused.wall, full.cpu / reused.cpu);
  return 0;
}

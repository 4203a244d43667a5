// skyfarm-farm-bench: the scheduler at scale, by simulation (farm_sim.h):
// the real broker and job service with simulated workers that render nothing.
//
//   skyfarm-farm-bench [--workers 1000] [--units 100000] [--jobs 1] [--slots 2] [--prefetch 16]
//                      [--unit-ms 0] [--width 1] [--height 1] [--batches 64]
//                      [--runs 1] [--timeout 600] [--data-dir DIR] [--json]
//
//   --workers    simulated workers (DEALER sockets in this process)
//   --units      units of work over all jobs (rounded up to whole passes)
//   --jobs       jobs the units are shared among (submitted together)
//   --slots      credit each worker announces in its READY
//   --prefetch   units each worker accepts beyond its slots (READY "prefetch",
//                default 16 as skyfarm-worker with 2 slots; 0: none)
//   --unit-ms    simulated render time of a unit (0: answer at once)
//   --width --height --batches   each job's request (tiny units by default:
//                one pixel, 64 wavelength batches, 16-sample passes)
//   --runs       runs; the table shows each and their median
//   --timeout    seconds before a run gives up (it then counts as failed)
//   --data-dir   the server's data directory (default: a fresh temporary one)
//   --json       one JSON object per run and one for the median, no table
//   --log        the broker's log lines on standard error
// Exit status: 0 when every run completed every job, 1 when one did not, 2
// for bad flags.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/tools/farm_sim.h"

namespace {

using skyfarm::server::FarmSimOptions;
using skyfarm::server::FarmSimResult;

constexpr const char* kUsage =
    "usage: skyfarm-farm-bench [--workers N] [--units N] [--jobs N] [--slots N] [--prefetch N] [--unit-ms MS]\n"
    "                          [--width W] [--height H] [--batches B] [--runs R] [--timeout S]\n"
    "                          [--data-dir DIR] [--no-curve] [--json] [--log]\n";

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2.0;
}

nlohmann::json to_json(const FarmSimResult& r) {
  nlohmann::json jobs = nlohmann::json::array();
  for (const auto& j : r.jobs)
    jobs.push_back({{"id", j.id}, {"state", j.state}, {"units_done", j.units_done}, {"units_total", j.units_total}});
  return {{"all_done", r.all_done},
          {"units", r.units_expected},
          {"units_merged", r.units_merged},
          {"results_sent", r.results_sent},
          {"seconds", r.seconds},
          {"units_per_second", r.units_per_second},
          {"latency_p50_ms", r.latency_p50_ms},
          {"latency_p99_ms", r.latency_p99_ms},
          {"latency_max_ms", r.latency_max_ms},
          {"rss_start_mb", r.rss_start_mb},
          {"rss_peak_mb", r.rss_peak_mb},
          {"rss_end_mb", r.rss_end_mb},
          {"units_sent", r.broker.units_sent},
          {"jobs", jobs}};
}

void print_row(const char* label, double units_s, double seconds, double p50, double p99, double rss0, double peak,
               double rss1) {
  std::printf("%-8s %10.0f %9.2f %9.2f %9.2f %9.1f %9.1f %9.1f\n", label, units_s, seconds, p50, p99, rss0, peak,
              rss1);
}

}  // namespace

int main(int argc, char** argv) {
  FarmSimOptions o;
  int runs = 1;
  bool json = false;
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
        return args[++i];
      };
      auto integer = [&](long long lo, long long hi) {
        const std::string& v = value();
        std::size_t used = 0;
        long long n = 0;
        try {
          n = std::stoll(v, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != v.size() || n < lo || n > hi)
          throw std::invalid_argument(a + ": '" + v + "' is not an integer in [" + std::to_string(lo) + ", " +
                                      std::to_string(hi) + "]");
        return n;
      };
      auto real = [&]() {
        const std::string& v = value();
        std::size_t used = 0;
        double x = -1.0;
        try {
          x = std::stod(v, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != v.size() || !(x >= 0.0)) throw std::invalid_argument(a + ": '" + v + "' is not a number >= 0");
        return x;
      };
      if (a == "--workers") o.workers = static_cast<int>(integer(1, 100000));
      else if (a == "--units") o.units = integer(1, 1LL << 40);
      else if (a == "--jobs") o.jobs = static_cast<int>(integer(1, 10000));
      else if (a == "--slots") o.slots = static_cast<int>(integer(1, 1024));
      else if (a == "--prefetch") o.prefetch = static_cast<int>(integer(0, 1024));
      else if (a == "--unit-ms") o.unit_ms = real();
      else if (a == "--width") o.width = static_cast<int>(integer(1, 65536));
      else if (a == "--height") o.height = static_cast<int>(integer(1, 65536));
      else if (a == "--batches") o.batches = static_cast<int>(integer(1, 64));
      else if (a == "--runs") runs = static_cast<int>(integer(1, 100));
      else if (a == "--timeout") o.timeout_s = real();
      else if (a == "--data-dir") o.data_dir = value();
      else if (a == "--no-curve") o.curve = false;
      else if (a == "--json") json = true;
      else if (a == "--log") o.log = [](std::string_view line) { std::cerr << line << "\n"; };
      else if (a == "--help" || a == "-h") {
        std::cout << kUsage;
        return 0;
      } else {
        throw std::invalid_argument("unknown flag " + a);
      }
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "skyfarm-farm-bench: " << e.what() << "\n" << kUsage;
    return 2;
  }

  std::vector<FarmSimResult> results;
  bool ok = true;
  if (!json)
    std::printf("farm simulation: %d workers x %d slots (+%d prefetch), %lld units in %d job(s), unit %.1f ms\n"
                "%-8s %10s %9s %9s %9s %9s %9s %9s\n",
                o.workers, o.slots, o.prefetch, static_cast<long long>(o.units), o.jobs, o.unit_ms, "run", "units/s", "seconds",
                "p50 ms", "p99 ms", "rss0 MB", "peak MB", "end MB");
  for (int r = 0; r < runs; ++r) {
    FarmSimResult res;
    try {
      res = skyfarm::server::run_farm_sim(o);
    } catch (const std::exception& e) {
      std::cerr << "skyfarm-farm-bench: " << e.what() << "\n";
      return 2;
    }
    ok = ok && res.all_done;
    if (json) {
      nlohmann::json j = to_json(res);
      j["run"] = r + 1;
      std::cout << j.dump() << std::endl;
    } else {
      print_row(("#" + std::to_string(r + 1)).c_str(), res.units_per_second, res.seconds, res.latency_p50_ms,
                res.latency_p99_ms, res.rss_start_mb, res.rss_peak_mb, res.rss_end_mb);
      if (!res.all_done)
        for (const auto& j : res.jobs)
          std::printf("  job %s: %s, %lld of %lld units\n", j.id.c_str(), j.state.c_str(),
                      static_cast<long long>(j.units_done), static_cast<long long>(j.units_total));
    }
    results.push_back(std::move(res));
  }
  auto med = [&](double FarmSimResult::*field) {
    std::vector<double> v;
    for (const auto& r : results) v.push_back(r.*field);
    return median(v);
  };
  if (json) {
    std::cout << nlohmann::json{{"median", true},
                                {"runs", runs},
                                {"all_done", ok},
                                {"workers", o.workers},
                                {"slots", o.slots},
                                {"prefetch", o.prefetch},
                                {"jobs", o.jobs},
                                {"units", results.front().units_expected},
                                {"unit_ms", o.unit_ms},
                                {"units_per_second", med(&FarmSimResult::units_per_second)},
                                {"seconds", med(&FarmSimResult::seconds)},
                                {"latency_p50_ms", med(&FarmSimResult::latency_p50_ms)},
                                {"latency_p99_ms", med(&FarmSimResult::latency_p99_ms)},
                                {"rss_start_mb", med(&FarmSimResult::rss_start_mb)},
                                {"rss_peak_mb", med(&FarmSimResult::rss_peak_mb)},
                                {"rss_end_mb", med(&FarmSimResult::rss_end_mb)}}
                     .dump()
              << std::endl;
  } else if (runs > 1) {
    print_row("median", med(&FarmSimResult::units_per_second), med(&FarmSimResult::seconds),
              med(&FarmSimResult::latency_p50_ms), med(&FarmSimResult::latency_p99_ms),
              med(&FarmSimResult::rss_start_mb), med(&FarmSimResult::rss_peak_mb), med(&FarmSimResult::rss_end_mb));
  }
  return ok ? 0 : 1;
}

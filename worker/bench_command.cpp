#include "worker/bench_command.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/render/local_render.h"
#include "common/render/parallel.h"
#include "worker/bench_convergence.h"
#include "worker/bench_efficiency.h"
#include "worker/bench_lut_clouds.h"
#include "worker/bench_lut_vs_path.h"
#include "worker/bench_objects.h"
#include "worker/bench_sky_accuracy.h"
#include "worker/cli_io.h"
#include "worker/demo_requests.h"

namespace skyfarm {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Timed {
  double seconds = 0.0;
  PathCounters counters;
};

// Renders a parsed request into memory (no files) with `threads` threads.
Timed render_request(const api::RenderRequest& request, int threads) {
  const auto t0 = std::chrono::steady_clock::now();
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  Image image(setup.plan.width, setup.plan.height);
  Timed t;
  t.counters = render_image(renderer, &image, threads).counters;
  t.seconds = seconds_since(t0);
  return t;
}

void bench_paths(int repeat) {
  // Ground-level equirectangular views, one thread: paths per second per core.
  const struct {
    const char* name;
    const char* json;
  } scenes[] = {
      {"noon_equirect", R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180},
        "camera": {"projection": "equirectangular", "width": 128, "height": 64},
        "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 8}})"},
      {"sunset_equirect", R"({"sun": {"zenith_deg": 90, "azimuth_deg": 270},
        "camera": {"projection": "equirectangular", "width": 128, "height": 64},
        "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 8}})"},
  };
  for (const auto& s : scenes) {
    const api::RenderRequest request = api::parse_render_request(s.json);
    std::vector<double> rates;
    std::uint64_t paths = 0;
    for (int i = 0; i < repeat; ++i) {
      const Timed t = render_request(request, 1);
      rates.push_back(static_cast<double>(t.counters.paths) / t.seconds);
      paths = t.counters.paths;
    }
    std::cout << nlohmann::json{{"bench", "paths_per_second_per_core"}, {"scene", s.name},
                                {"wavelengths_per_path", kWavelengthsPerPath}, {"paths_per_run", paths},
                                {"repeat", repeat}, {"median", median(rates)}}
                     .dump()
              << std::endl;
  }
}

void bench_demo(int repeat) {
  for (const auto& demo : demo_requests()) {
    const api::RenderRequest request = api::parse_render_request(demo.json);
    std::vector<double> times;
    for (int i = 0; i < repeat; ++i) times.push_back(render_request(request, 0).seconds);
    std::cout << nlohmann::json{{"bench", "demo_render_wall_time_s"}, {"scene", demo.name},
                                {"threads", resolve_thread_count(0)}, {"repeat", repeat}, {"median", median(times)}}
                     .dump()
              << std::endl;
  }
}

void bench_memory() {
  const api::RenderRequest request = api::parse_render_request(R"({
    "sun": {"zenith_deg": 40, "azimuth_deg": 120},
    "camera": {"projection": "equirectangular", "width": 4096, "height": 2048},
    "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 1}})");
  const Timed t = render_request(request, 0);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::cout << nlohmann::json{{"bench", "peak_memory_4096x2048_equirect"},
                              {"peak_rss_mb", static_cast<double>(usage.ru_maxrss) / 1024.0},
                              {"seconds", t.seconds}}
                   .dump()
            << std::endl;
}

}  // namespace

int run_bench_command(const std::vector<std::string>& args) {
  std::string which = "all";
  int repeat = 5;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--repeat" && i + 1 < args.size()) {
      repeat = std::max(1, std::atoi(args[++i].c_str()));
    } else if (args[i] == "convergence") {
      return run_bench_convergence(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "lut-vs-path") {
      return run_bench_lut_vs_path(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "lut-clouds") {
      return run_bench_lut_clouds(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "objects") {
      return run_bench_objects(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "sky-accuracy") {
      return run_bench_sky_accuracy(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "efficiency") {
      return run_bench_efficiency(std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(i), args.end()));
    } else if (args[i] == "paths" || args[i] == "demo" || args[i] == "memory" || args[i] == "all") {
      which = args[i];
    } else {
      std::cerr << "usage: skyfarm-worker bench [paths|demo|memory|all] [--repeat N]\n"
                   "       skyfarm-worker bench convergence [--out DIR] [--passes N]\n"
                   "       skyfarm-worker bench efficiency [--samples N] [--sun-zenith DEG ...] [--shadow-scale S] "
                   "[--sunlit-segments]\n"
                   "       skyfarm-worker bench lut-vs-path [--out DIR] [--spp N]\n"
                   "       skyfarm-worker bench lut-clouds [--out DIR] [--spp N]\n"
                   "       skyfarm-worker bench sky-accuracy [--reference FILE] [--out DIR] [--cases N] [--threads N] "
                   "[--repeat N] [--reference-samples N]\n"
                   "       skyfarm-worker bench objects [paths|mirror|all] [--repeat N] [--passes P] [--seeds K] "
                   "[--reference-passes R]\n";
      return 2;
    }
  }
  if (which == "paths" || which == "all") bench_paths(repeat);
  if (which == "demo" || which == "all") bench_demo(std::min(repeat, 3));
  // Last: peak RSS is a high-water mark of the whole process.
  if (which == "memory" || which == "all") bench_memory();
  return 0;
}

}  // namespace skyfarm

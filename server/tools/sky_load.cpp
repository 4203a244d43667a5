// skyfarm-sky-load: a tiny keep-alive HTTP load generator for the sky
// look-ups (scripts/bench-sky.sh).  N threads, each with its own keep-alive
// httplib::Client, GET one path for D seconds; prints requests/s and the
// latency percentiles of the successful requests.
//
//   skyfarm-sky-load --port P [--host 127.0.0.1] --path '/v1/sky?...'
//                    [--threads 2] [--seconds 5] [--vary-view]
//   skyfarm-sky-load --port P --path '/v1/sky/envmap.exr?...' --requests 2
//
// --vary-view appends view_zenith and view_azimuth, drawn per request on a
// 0.5-degree grid (so the JSON answers differ but the table is shared).
// --requests N sends N requests one after the other on one connection and
// prints each one's time (the first of a new key is the cold one).
// Output: one line of key=value pairs.
#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

struct Options {
  std::string host = "127.0.0.1";
  int port = 8080;
  std::string path = "/healthz";
  int threads = 2;
  double seconds = 5.0;
  bool vary_view = false;
  int requests = 0;
};

[[noreturn]] void usage(const char* why) {
  std::cerr << "skyfarm-sky-load: " << why << "\n"
            << "usage: skyfarm-sky-load --port P [--host H] --path PATH [--threads N] [--seconds D] [--vary-view]\n"
            << "       skyfarm-sky-load --port P [--host H] --path PATH --requests N\n";
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(("missing value after " + a).c_str());
      return argv[++i];
    };
    if (a == "--host") o.host = value();
    else if (a == "--port") o.port = std::stoi(value());
    else if (a == "--path") o.path = value();
    else if (a == "--threads") o.threads = std::max(1, std::stoi(value()));
    else if (a == "--seconds") o.seconds = std::stod(value());
    else if (a == "--requests") o.requests = std::stoi(value());
    else if (a == "--vary-view") o.vary_view = true;
    else usage(("unknown argument " + a).c_str());
  }
  return o;
}

double percentile(std::vector<double>& v, double p) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(p * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

httplib::Client client(const Options& o) {
  httplib::Client c(o.host, o.port);
  c.set_keep_alive(true);
  c.set_connection_timeout(5);
  c.set_read_timeout(600);
  return c;
}

int sequential(const Options& o) {
  auto c = client(o);
  std::cout << "path=" << o.path;
  for (int i = 0; i < o.requests; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = c.Get(o.path);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      std::cout << " request" << i << "=error(" << httplib::to_string(r.error()) << ")\n";
      return 1;
    }
    std::cout << " request" << i << "_ms=" << ms << " status" << i << "=" << r->status << " bytes" << i << "="
              << r->body.size();
  }
  std::cout << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (o.requests > 0) return sequential(o);

  std::atomic<bool> stop{false};
  std::vector<std::vector<double>> latencies(static_cast<std::size_t>(o.threads));
  std::vector<std::uint64_t> errors(static_cast<std::size_t>(o.threads), 0);
  std::vector<std::thread> pool;
  const auto start = std::chrono::steady_clock::now();
  for (int t = 0; t < o.threads; ++t)
    pool.emplace_back([&, t] {
      auto c = client(o);
      std::mt19937_64 rng(static_cast<std::uint64_t>(t) * 7919 + 1);
      std::uniform_int_distribution<int> zen(0, 180), azi(0, 719);
      auto& lat = latencies[static_cast<std::size_t>(t)];
      lat.reserve(1 << 20);
      std::string path;
      while (!stop.load(std::memory_order_relaxed)) {
        path = o.path;
        if (o.vary_view) {
          path += (path.find('?') == std::string::npos ? "?" : "&");
          path += "view_zenith=" + std::to_string(zen(rng) * 0.5) + "&view_azimuth=" + std::to_string(azi(rng) * 0.5);
        }
        const auto t0 = std::chrono::steady_clock::now();
        auto r = c.Get(path);
        const auto t1 = std::chrono::steady_clock::now();
        if (!r || r->status != 200) {
          ++errors[static_cast<std::size_t>(t)];
          if (!r) std::this_thread::sleep_for(std::chrono::milliseconds(1));
          continue;
        }
        lat.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      }
    });
  std::this_thread::sleep_for(std::chrono::duration<double>(o.seconds));
  stop = true;
  for (auto& th : pool) th.join();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<double> all;
  std::uint64_t errs = 0;
  for (std::size_t t = 0; t < latencies.size(); ++t) {
    all.insert(all.end(), latencies[t].begin(), latencies[t].end());
    errs += errors[t];
  }
  const std::size_t ok = all.size();
  char line[512];
  std::snprintf(line, sizeof line,
                "path=%s threads=%d seconds=%.2f requests=%zu errors=%llu rps=%.0f median_us=%.1f p90_us=%.1f "
                "p99_us=%.1f",
                o.path.c_str(), o.threads, elapsed, ok, static_cast<unsigned long long>(errs), double(ok) / elapsed,
                percentile(all, 0.5), percentile(all, 0.9), percentile(all, 0.99));
  std::cout << line << std::endl;
  return errs > 0 && ok == 0 ? 1 : 0;
}

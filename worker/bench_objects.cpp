#include "worker/bench_objects.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/core/constants.h"
#include "common/film/image.h"
#include "common/render/local_render.h"
#include "common/render/render_setup.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {
namespace {

using Json = nlohmann::json;

constexpr double kCameraHeightM = 1.6;
constexpr double kBallRadiusM = 0.5;
const glm::dvec3 kMirrorCentre{-1.3, 5.0, 0.5};  // ground-origin east-north-up, m

// The three reference balls (api/examples/objects_reference_balls.json).
Json reference_balls() {
  return Json::parse(R"([
    {"name": "chrome ball", "shape": "sphere", "material": {"name": "chrome", "roughness": 0},
     "translate_m": [-1.3, 5, 0.5], "scale": 0.5},
    {"name": "grey ball", "shape": "sphere", "albedo": 0.18, "translate_m": [0, 5, 0.5], "scale": 0.5},
    {"name": "white ball", "shape": "sphere", "albedo": 0.8, "translate_m": [1.3, 5, 0.5], "scale": 0.5}])");
}

// A view of the balls.  `closeup`: 64x64, fov 15, centred on the mirror ball.
Json view_request(bool closeup, bool with_balls, int spp, std::uint64_t seed) {
  Json camera = {{"projection", "perspective"}, {"width", 96}, {"height", 54}, {"fov_deg", 55}, {"pitch_deg", -10}};
  if (closeup) {
    const glm::dvec3 to = kMirrorCentre - glm::dvec3(0.0, 0.0, kCameraHeightM);
    const double yaw = std::atan2(to.x, to.y) * 180.0 / kPi;
    const double pitch = std::atan2(to.z, std::hypot(to.x, to.y)) * 180.0 / kPi;
    camera = {{"projection", "perspective"}, {"width", 64},  {"height", 64},
              {"fov_deg", 15},               {"yaw_deg", yaw}, {"pitch_deg", pitch}};
  }
  Json r = {{"location", {{"latitude_deg", 47.05}, {"altitude_m", kCameraHeightM}}},
            {"sun", {{"zenith_deg", 30}, {"azimuth_deg", 180}}},
            {"camera", camera},
            {"atmosphere", {{"ground", {{"material", {{"name", "grass"}}}}}}},
            {"spectral", {{"batches", 1}}},
            {"quality", {{"samples_per_pixel", spp}}},
            {"seed", seed}};
  if (with_balls) r["objects"] = reference_balls();
  return r;
}

RenderSetup setup_of(const Json& request) {
  return make_render_setup(api::render_spec(api::parse_render_request(request.dump())));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// CPU seconds of this process: on a shared machine, the work a single
// rendering thread did, whatever else ran.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void bench_paths(int repeat) {
  for (const bool closeup : {false, true}) {
    double rate_without = 0.0;
    for (const bool with_balls : {false, true}) {
      const Json request = view_request(closeup, with_balls, 8, 1);
      std::vector<double> rates, wall_rates;
      std::uint64_t paths = 0;
      for (int i = 0; i < repeat; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const double cpu0 = process_cpu_seconds();
        const RenderSetup setup = setup_of(request);
        const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
        Image image(setup.plan.width, setup.plan.height);
        paths = render_image(renderer, &image, 1).counters.paths;
        const double cpu = process_cpu_seconds() - cpu0;
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        rates.push_back(static_cast<double>(paths) / cpu);
        wall_rates.push_back(static_cast<double>(paths) / wall);
      }
      const double rate = median(rates);
      if (!with_balls) rate_without = rate;
      Json line = {{"bench", "objects_paths_per_second_per_core"},
                   {"view", closeup ? "mirror_closeup" : "reference_view"},
                   {"scene", with_balls ? "reference_balls" : "empty"},
                   {"paths_per_run", paths},
                   {"repeat", repeat},
                   {"median", rate},
                   {"median_wall", median(wall_rates)}};
      if (with_balls && rate_without > 0.0) line["relative_to_empty"] = rate / rate_without;
      std::cout << line.dump() << std::endl;
    }
  }
}

// Luminance per pixel of a film (0 where never traced).
std::vector<double> luminance_of(const std::vector<FilmTile>& film, int width, int height) {
  std::vector<double> Y(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0);
  for (const auto& tile : film)
    for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
      for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x)
        if (const auto m = tile.mean_xyz(x, y)) Y[static_cast<std::size_t>(y * width + x)] = m->y;
  return Y;
}

// Where a ray from the camera (ground-origin ENU (0, 0, 1.6)) along d meets
// the chrome ball, as the direction it leaves the mirror in; nothing if it misses.
std::optional<glm::dvec3> reflected(const glm::dvec3& d) {
  const glm::dvec3 o(0.0, 0.0, kCameraHeightM);
  const glm::dvec3 oc = o - kMirrorCentre;
  const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - kBallRadiusM * kBallRadiusM;
  if (b * b - c <= 0.0 || -b <= 0.0) return std::nullopt;
  const double t = -b - std::sqrt(b * b - c);
  const glm::dvec3 n = (o + t * d - kMirrorCentre) / kBallRadiusM;
  return d - 2.0 * glm::dot(d, n) * n;
}

// The pixels wholly on the chrome ball (all four corners' rays meet it),
// without those that may reflect the sun: a mirror sends a pixel's rays into
// a cone several degrees wide, so a few of them find the 0.5 deg disk and
// bring 1e5 x the sky's radiance; the reference cannot pin those pixels.  A
// pixel is left out when the sun lies within its corners' spread (plus half
// a degree) of its centre's reflection.
std::vector<bool> mirror_pixels(const Camera& camera, int width, int height, const glm::dvec3& sun, int* sun_pixels) {
  std::vector<bool> on(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), false);
  *sun_pixels = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Ray centre_ray;
      if (!camera.generate_ray(x, y, 0.5, 0.5, &centre_ray)) continue;
      const auto centre = reflected(centre_ray.d);
      bool all = centre.has_value();
      double spread = 0.0;
      for (const double jx : {0.0, 0.999})
        for (const double jy : {0.0, 0.999}) {
          Ray ray;
          const auto r = all && camera.generate_ray(x, y, jx, jy, &ray) ? reflected(ray.d) : std::nullopt;
          all = all && r.has_value();
          if (r) spread = std::max(spread, std::acos(std::clamp(glm::dot(*r, *centre), -1.0, 1.0)));
        }
      if (!all) continue;
      if (std::acos(std::clamp(glm::dot(*centre, sun), -1.0, 1.0)) < spread + 0.5 * kPi / 180.0) {
        ++*sun_pixels;
        continue;
      }
      on[static_cast<std::size_t>(y * width + x)] = true;
    }
  return on;
}

struct PassPoint {
  int pass = 0;
  double seconds = 0.0;
  double error = 0.0;
};

// One progressive close-up render; the error after passes 1, 2, 4, ...
std::vector<PassPoint> mirror_run(int passes, std::uint64_t seed, const std::vector<double>& ref,
                                  const std::vector<bool>& keep) {
  const RenderSetup setup = setup_of(view_request(true, true, passes * 16, seed));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  std::vector<PassPoint> points;
  StopCriteria stop;
  stop.after_pass = [&](int pass, const std::vector<FilmTile>& film, double elapsed) {
    if ((pass & (pass - 1)) != 0 && pass != passes) return;  // powers of two and the last
    const std::vector<double> Y = luminance_of(film, setup.plan.width, setup.plan.height);
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < Y.size(); ++i) {
      if (!keep[i]) continue;
      num += (Y[i] - ref[i]) * (Y[i] - ref[i]);
      den += ref[i] * ref[i];
    }
    points.push_back({pass, elapsed, den > 0.0 ? std::sqrt(num / den) : 0.0});
  };
  Image image(setup.plan.width, setup.plan.height);
  render_image_progressive(renderer, &image, 0, stop);
  return points;
}

void bench_mirror(int passes, int seeds, int reference_passes) {
  // The reference, and the pixels it is compared on.
  const RenderSetup setup = setup_of(view_request(true, true, reference_passes * 16, 987654321));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  std::vector<double> ref;
  StopCriteria stop;
  stop.after_pass = [&](int pass, const std::vector<FilmTile>& film, double) {
    if (pass == setup.plan.passes) ref = luminance_of(film, setup.plan.width, setup.plan.height);
  };
  Image image(setup.plan.width, setup.plan.height);
  const auto t0 = std::chrono::steady_clock::now();
  render_image_progressive(renderer, &image, 0, stop);
  const double reference_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int sun_pixels = 0;
  const std::vector<bool> keep = mirror_pixels(*setup.camera, setup.plan.width, setup.plan.height,
                                               setup.scene->sun().direction(), &sun_pixels);
  std::vector<double> on_ball;
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) on_ball.push_back(ref[i]);
  const double ball_median = median(on_ball);
  std::cout << Json{{"bench", "objects_mirror_reference"},
                    {"samples_per_pixel", reference_passes * 16},
                    {"seconds", reference_s},
                    {"mirror_pixels", on_ball.size()},
                    {"sun_reflection_pixels_left_out", sun_pixels},
                    {"ball_median_luminance", ball_median}}
                   .dump()
            << std::endl;

  std::vector<std::vector<PassPoint>> runs;
  for (int s = 1; s <= seeds; ++s) runs.push_back(mirror_run(passes, static_cast<std::uint64_t>(s), ref, keep));
  std::vector<double> log_t, log_e;
  for (std::size_t k = 0; k < runs.front().size(); ++k) {
    std::vector<double> seconds, errors;
    for (const auto& run : runs) {
      seconds.push_back(run[k].seconds);
      errors.push_back(run[k].error);
    }
    const double t = median(seconds), e = median(errors);
    std::cout << Json{{"bench", "objects_mirror_error"},
                      {"samples_per_pixel", runs.front()[k].pass * 16},
                      {"seeds", seeds},
                      {"median_seconds", t},
                      {"median_relative_rms", e},
                      {"min_relative_rms", *std::min_element(errors.begin(), errors.end())},
                      {"max_relative_rms", *std::max_element(errors.begin(), errors.end())}}
                     .dump()
              << std::endl;
    if (t > 0.0 && e > 0.0) log_t.push_back(std::log(t)), log_e.push_back(std::log(e));
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(log_t.size());
  for (std::size_t i = 0; i < log_t.size(); ++i) {
    sx += log_t[i];
    sy += log_e[i];
    sxx += log_t[i] * log_t[i];
    sxy += log_t[i] * log_e[i];
  }
  const double slope = n > 1 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0.0;
  std::cout << Json{{"bench", "objects_mirror_slope"}, {"fitted_log_error_per_log_time", slope}}.dump() << std::endl;
}

}  // namespace

int run_bench_objects(const std::vector<std::string>& args) {
  std::string which = "all";
  int repeat = 5, passes = 32, seeds = 3, reference_passes = 256;
  for (std::size_t i = 1; i < args.size(); ++i) {  // args[0] is "objects"
    if (args[i] == "--repeat" && i + 1 < args.size()) {
      repeat = std::max(1, std::atoi(args[++i].c_str()));
    } else if (args[i] == "--passes" && i + 1 < args.size()) {
      passes = std::max(1, std::atoi(args[++i].c_str()));
    } else if (args[i] == "--seeds" && i + 1 < args.size()) {
      seeds = std::max(1, std::atoi(args[++i].c_str()));
    } else if (args[i] == "--reference-passes" && i + 1 < args.size()) {
      reference_passes = std::max(1, std::atoi(args[++i].c_str()));
    } else if (args[i] == "paths" || args[i] == "mirror" || args[i] == "all") {
      which = args[i];
    } else {
      std::cerr << "usage: skyfarm-worker bench objects [paths|mirror|all] [--repeat N] [--passes P] [--seeds K]"
                   " [--reference-passes R]\n";
      return 2;
    }
  }
  if (which == "paths" || which == "all") bench_paths(repeat);
  if (which == "mirror" || which == "all") bench_mirror(passes, seeds, reference_passes);
  return 0;
}

}  // namespace skyfarm

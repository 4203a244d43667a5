#include "worker/bench_convergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "api/render_spec.h"
#include "common/film/error_estimate.h"
#include "common/image/exr_writer.h"
#include "common/film/image.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

struct Scene_ {
  const char* name;
  const char* json;  // without quality and seed
};

// Small frames (64x32 equirect, 1 batch) so references converge in minutes.
const Scene_ kScenes[] = {
    {"noon", R"("sun": {"zenith_deg": 30, "azimuth_deg": 180})"},
    {"sun85", R"("sun": {"zenith_deg": 85, "azimuth_deg": 180})"},
    {"sunset", R"("sun": {"zenith_deg": 90, "azimuth_deg": 180})"},
    {"twilight96", R"("sun": {"zenith_deg": 96, "azimuth_deg": 180})"},
    {"orbit400km", R"("sun": {"zenith_deg": 45, "azimuth_deg": 180}, "location": {"altitude_m": 400000})"},
    {"haze", R"("sun": {"zenith_deg": 40, "azimuth_deg": 180}, "atmosphere": {"aerosol": {"optical_depth_550": 0.5}})"},
    // A summer afternoon in Paris, clear and with scattered cumulus (the
    // clouds' efficiency against the clear sky's).
    {"paris_clear", R"("location": {"latitude_deg": 48.8566, "longitude_deg": 2.3522},)"
                    R"( "time": "2026-07-15T17:00:00+02:00")"},
    {"paris_cumulus", R"("location": {"latitude_deg": 48.8566, "longitude_deg": 2.3522},)"
                      R"( "time": "2026-07-15T17:00:00+02:00", "clouds": {"layers": [{"type": "cumulus",)"
                      R"( "coverage": 0.35, "base_m": 1400, "thickness_m": 1200, "seed": 7,)"
                      R"( "wind": {"speed_m_s": 8, "from_deg": 270}}]})"},
};

std::string request_json(const Scene_& s, int spp, int seed) {
  return std::string("{") + s.json +
         R"(, "camera": {"projection": "equirectangular", "width": 64, "height": 32}, "spectral": {"batches": 1},)"
         R"( "quality": {"samples_per_pixel": )" + std::to_string(spp) + R"(}, "output": {"half": false}, "seed": )" +
         std::to_string(seed) + "}";
}

// Luminance per pixel of a film (0 where never traced); a mirrored plan's
// right half is its left half reflected, as in the images.
std::vector<double> luminance_of(const std::vector<FilmTile>& film, int width, int height, bool mirrored) {
  std::vector<double> Y(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0);
  auto at = [&](int x, int y) -> double& { return Y[static_cast<std::size_t>(y * width + x)]; };
  for (const auto& tile : film)
    for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
      for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x)
        if (const auto m = tile.mean_xyz(x, y)) at(x, y) = m->y;
  if (mirrored)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width / 2; ++x) at(width - 1 - x, y) = at(x, y);
  return Y;
}

// The sun disk's pixels (a 5x5 block around its centre): a few pixels 1e6
// times brighter than the sky, hit or missed by chance, would otherwise be
// the whole luminance-weighted error.  Both errors leave them out.
std::vector<bool> sky_mask(const RenderSetup& setup) {
  std::vector<bool> keep(64 * 32, true);
  double fx = 0.0, fy = 0.0;
  if (!setup.scene->sun().is_point() && setup.camera->direction_to_film(setup.scene->sun().direction(), &fx, &fy))
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        const int x = (static_cast<int>(fx) + dx + 64) % 64, y = static_cast<int>(fy) + dy;
        if (y >= 0 && y < 32) keep[static_cast<std::size_t>(y * 64 + x)] = false;
      }
  return keep;
}

// True luminance-weighted relative RMS error: sqrt(sum (Y - Y_ref)^2 / sum Y_ref^2).
double true_error(const std::vector<double>& Y, const std::vector<double>& ref, const std::vector<bool>& keep) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < Y.size(); ++i) {
    if (!keep[i]) continue;
    num += (Y[i] - ref[i]) * (Y[i] - ref[i]);
    den += ref[i] * ref[i];
  }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

// Where the true error is (--breakdown): each row's share of sum (Y - Y_ref)^2
// and of sum Y_ref^2, and the pixel with the largest share (at twilight a
// single path a thousand times the pixel's mean can be most of the error).
void print_error_breakdown(const std::vector<double>& Y, const std::vector<double>& ref, const std::vector<bool>& keep) {
  double num = 0.0, den = 0.0, worst = 0.0;
  std::vector<double> row_num(32, 0.0), row_den(32, 0.0);
  std::size_t worst_i = 0;
  for (std::size_t i = 0; i < Y.size(); ++i) {
    if (!keep[i]) continue;
    const double d2 = (Y[i] - ref[i]) * (Y[i] - ref[i]);
    num += d2;
    den += ref[i] * ref[i];
    row_num[i / 64] += d2;
    row_den[i / 64] += ref[i] * ref[i];
    if (d2 > worst) worst = d2, worst_i = i;
  }
  if (!(num > 0.0) || !(den > 0.0)) return;
  for (std::size_t r = 0; r < 32; ++r)
    std::cout << "  row " << r << ": share of squared error " << row_num[r] / num << ", of luminance^2 "
              << row_den[r] / den << "\n";
  std::cout << "  worst pixel x " << worst_i % 64 << " y " << worst_i / 64 << ": share " << worst / num << ", Y "
            << Y[worst_i] << " against " << ref[worst_i] << "\n";
}

// The renderer's own estimate over the same pixels (ErrorSums::relative_rms).
double estimated_error(const std::vector<FilmTile>& film, const std::vector<bool>& keep) {
  ErrorSums sums;
  for (const auto& tile : film)
    for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
      for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
        if (!keep[static_cast<std::size_t>(y * 64 + x)]) continue;
        const auto m = tile.mean_xyz(x, y);
        const auto v = tile.luminance_variance_of_mean(x, y);
        if (!m || !v) continue;
        sums.sum_var += *v;
        sums.sum_Y2 += m->y * m->y;
      }
  return sums.relative_rms().value_or(0.0);
}

// The reference: many passes with another seed, cached as raw doubles.
std::vector<double> reference(const Scene_& s, int passes, const fs::path& dir) {
  const fs::path cache = dir / (std::string(s.name) + "_reference_" + std::to_string(passes) + ".bin");
  std::vector<double> Y(64 * 32, 0.0);
  if (std::ifstream in(cache, std::ios::binary); in && in.read(reinterpret_cast<char*>(Y.data()), Y.size() * sizeof(double)))
    return Y;
  const auto request = api::parse_render_request(request_json(s, passes * 16, 987654321));
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  StopCriteria stop;
  stop.after_pass = [&](int pass, const std::vector<FilmTile>& film, double) {
    if (pass == setup.plan.passes) Y = luminance_of(film, 64, 32, setup.plan.mirrored);
  };
  Image image(64, 32);
  render_image_progressive(renderer, &image, 0, stop);
  std::ofstream(cache, std::ios::binary).write(reinterpret_cast<const char*>(Y.data()), static_cast<std::streamsize>(Y.size() * sizeof(double)));
  return Y;
}

// Least-squares slope of log(error) against log(time).
double fitted_slope(const std::vector<double>& t, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (e[i] <= 0.0 || t[i] <= 0.0) continue;
    const double x = std::log(t[i]), y = std::log(e[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    n += 1;
  }
  return n > 1 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0.0;
}

}  // namespace

int run_bench_convergence(const std::vector<std::string>& args) {
  fs::path dir = "skyfarm-convergence";
  int passes = 32, seed = 1;
  std::string only;
  IntegratorOptions options;
  std::optional<bool> roulette_control;  // the plan's choice unless given
  bool adaptive = false;                  // variance-aware sample allocation (sample_allocation.h)
  std::optional<bool> shadow_guide;      // the plan's choice unless given
  bool breakdown = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--out" && i + 1 < args.size()) dir = args[++i];
    else if (args[i] == "--scene" && i + 1 < args.size()) only = args[++i];
    else if (args[i] == "--forced-segments" && i + 1 < args.size())
      options.forced_collision_segments = std::atoi(args[++i].c_str());
    else if (args[i] == "--plain-ratio-tracking")
      options.residual_ratio_tracking = false;
    else if (args[i] == "--no-sunlit-in-shadow")
      options.sunlit_segments_in_shadow = false;
    else if (args[i] == "--sunlit-segments")
      options.explicit_single_scattering = true;
    else if (args[i] == "--passes" && i + 1 < args.size()) passes = std::max(2, std::atoi(args[++i].c_str()));
    else if (args[i] == "--seed" && i + 1 < args.size()) seed = std::atoi(args[++i].c_str());
    else if (args[i] == "--max-camera-scale" && i + 1 < args.size())
      options.max_camera_majorant_scale = std::atof(args[++i].c_str());
    else if (args[i] == "--rr-threshold-in-shadow" && i + 1 < args.size())
      options.rr_threshold_in_shadow = std::atof(args[++i].c_str());
    else if (args[i] == "--rr-start-depth" && i + 1 < args.size())
      options.rr_start_depth = std::atoi(args[++i].c_str());
    else if (args[i] == "--roulette-control")
      roulette_control = true;
    else if (args[i] == "--no-roulette-control")
      roulette_control = false;
    else if (args[i] == "--adaptive")
      adaptive = true;
    else if (args[i] == "--no-shadow-guide")
      shadow_guide = false;
    else if (args[i] == "--breakdown")
      breakdown = true;
    else if (args[i] != "convergence") {
      std::cerr << "usage: skyfarm-worker bench convergence [--out DIR] [--passes N] [--scene NAME]"
                   " [--forced-segments K] [--plain-ratio-tracking] [--sunlit-segments]\n"
                   "  [--no-sunlit-in-shadow] [--seed N] [--rr-threshold-in-shadow W] [--max-camera-scale S]\n"
                   "  [--roulette-control | --no-roulette-control] [--rr-start-depth D] [--adaptive]\n"
                   "  [--no-shadow-guide] [--breakdown]\n";
      return 2;
    }
  }
  fs::create_directories(dir);
  for (const Scene_& s : kScenes) {
    if (!only.empty() && only != s.name) continue;
    const std::vector<double> ref = reference(s, passes * 16, dir);
    const auto request = api::parse_render_request(request_json(s, passes * 16, seed));
    RenderSetup setup = make_render_setup(api::render_spec(request));
    if (roulette_control) setup.plan.roulette_control = *roulette_control;
    if (shadow_guide) setup.plan.shadow_guide = *shadow_guide;
    setup.plan.adaptive = adaptive;
    const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan, options);
    const std::vector<bool> keep = sky_mask(setup);
    std::vector<double> times, truths, estimates;
    std::ofstream csv(dir / (std::string(s.name) + ".csv"));
    csv << "elapsed_s,samples_per_pixel,true_relative_rms,estimated_relative_rms\n";
    StopCriteria stop;
    stop.after_pass = [&](int pass, const std::vector<FilmTile>& film, double elapsed) {
      const double est = estimated_error(film, keep);
      const double truth = true_error(luminance_of(film, 64, 32, setup.plan.mirrored), ref, keep);
      times.push_back(elapsed);
      truths.push_back(truth);
      estimates.push_back(est);
      csv << elapsed << "," << pass * 16 << "," << truth << "," << est << "\n";
      if (breakdown && pass == setup.plan.passes)
        print_error_breakdown(luminance_of(film, 64, 32, setup.plan.mirrored), ref, keep);
    };
    Image image(64, 32);
    render_image_progressive(renderer, &image, 0, stop);
    double worst = 1.0;
    for (std::size_t i = 0; i < truths.size(); ++i)
      if (truths[i] > 0.0 && estimates[i] > 0.0)
        worst = std::max(worst, std::max(estimates[i] / truths[i], truths[i] / estimates[i]));
    const double efficiency = truths.back() > 0.0 ? 1.0 / (truths.back() * truths.back() * times.back()) : 0.0;
    std::cout << nlohmann::json{{"bench", "convergence"},
                                {"scene", s.name},
                                {"final_true_relative_rms", truths.back()},
                                {"final_estimated_relative_rms", estimates.back()},
                                {"seconds", times.back()},
                                {"samples_per_pixel", passes * 16},
                                {"forced_collision_segments", options.forced_collision_segments},
                                {"roulette_control", setup.plan.roulette_control},
                                {"shadow_guide", setup.plan.shadow_guide},
                                {"adaptive", adaptive},
                                {"fitted_slope", fitted_slope(times, truths)},
                                {"worst_estimate_ratio", worst},
                                {"efficiency_1_over_err2_time", efficiency}}
                     .dump()
              << std::endl;
  }
  return 0;
}

}  // namespace skyfarm

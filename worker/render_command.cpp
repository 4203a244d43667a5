#include "worker/render_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <algorithm>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>

#include "api/field_error.h"
#include "api/probe_request.h"
#include "api/render_request.h"
#include "api/probe_answer.h"
#include "api/probe_spec.h"
#include "api/render_spec.h"
#include "common/core/constants.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "common/render/local_render.h"
#include "common/render/parallel.h"
#include "common/render/radiance_probe.h"
#include "worker/cli_io.h"
#include "worker/demo_requests.h"
#include "worker/request_assets.h"

namespace skyfarm {
namespace {

struct RenderArgs {
  std::string request, exr, png, asset_cache;
  int threads = 0;
  int png_bits = 8;
};

// Parses "REQUEST.json -o OUT.exr [--png OUT.png] [--threads N]"; returns an error text or "".
std::string parse_render_args(const std::vector<std::string>& args, RenderArgs* out) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if ((a == "-o" || a == "--output") && has_value) {
      out->exr = args[++i];
    } else if (a == "--png" && has_value) {
      out->png = args[++i];
    } else if (a == "--asset-cache" && has_value) {
      out->asset_cache = args[++i];
    } else if (a == "--png-16bit") {
      out->png_bits = 16;
    } else if (a == "--threads" && has_value) {
      try {
        out->threads = std::stoi(args[++i]);
      } catch (const std::exception&) {
        return "--threads: must be an integer, got '" + args[i] + "'";
      }
      if (out->threads < 0) return "--threads: must be >= 0 (0 = all cores)";
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      return "unknown or incomplete option '" + a + "'";
    } else if (out->request.empty()) {
      out->request = a;
    } else {
      return "unexpected argument '" + a + "'";
    }
  }
  if (out->request.empty()) return "a request file is required";
  if (out->exr.empty()) return "-o OUT.exr is required";
  return "";
}


}  // namespace

int render_to_files(const api::RenderRequest& request, const std::string& exr_path, const std::string& png_path,
                    int threads, const std::string& label, int png_bits = 8,
                    const assets::MeshSource* meshes = nullptr, const assets::VolumeSource* volumes = nullptr) {
  const auto t0 = std::chrono::steady_clock::now();
  const RenderSetup setup = make_render_setup(api::render_spec(request), meshes, volumes);
  const Scene& scene = *setup.scene;
  const RenderPlan& plan = setup.plan;
  const TileRenderer renderer(scene, *setup.camera, plan);
  ImageLayers layers;
  if (request.output.spectral_channels)
    layers.spectral = SpectralLayout{plan.lambda_min_nm, plan.lambda_max_nm, plan.batches};
  layers.relative_error = request.output.error_layer;
  Image image(plan.width, plan.height, layers);
  const bool open_ended = request.quality.target_relative_error || request.quality.time_limit_s;
  std::fprintf(stderr, "%s: %dx%d, %s%d spp%s, %d batches, %d tiles, sun at zenith %.3f deg azimuth %.3f deg\n",
               label.c_str(), plan.width, plan.height, open_ended ? "up to " : "", plan.samples_per_pixel,
               plan.adaptive ? " (mean, adaptive)" : "", plan.batches, plan.tile_count(),
               scene.sun().zenith_deg(), scene.sun().azimuth_deg());
  ProgressDisplay progress(label);
  const auto on_progress = [&](double fraction) { progress.update(fraction); };
  LocalRenderResult result;
  double samples = plan.samples_per_pixel;
  std::string stopped_by = "samples";
  if (request.quality.target_relative_error || request.quality.time_limit_s || plan.adaptive) {
    // Pass by pass over the whole frame, stopping (and allocating) like the farm does.
    const ProgressiveResult r = render_image_progressive(
        renderer, &image, threads, {request.quality.target_relative_error, request.quality.time_limit_s, {}}, on_progress);
    result = r;
    samples = r.samples_per_pixel;
    stopped_by = r.stopped_by;
    if (r.allocation)
      std::fprintf(stderr, "%s: adaptive samples per pass %d-%d after the pilot\n", label.c_str(),
                   r.allocation->min_samples_per_pass(), r.allocation->max_samples_per_pass());
  } else {
    result = render_image(renderer, &image, threads, on_progress);
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  api::set_render_metadata(&image, request, plan, scene.sun(), samples, result.error);

  ExrWriteOptions exr;
  exr.half = request.output.half;
  exr.spectral_channels = request.output.spectral_channels;
  exr.error_layer = request.output.error_layer;
  exr.latlong_envmap = request.camera.projection == Projection::kEquirectangular;
  exr.color_space = request.output.color_space;
  exr.units = request.output.units;
  exr.exposure_ev = request.output.exposure_ev;
  const ExrWriteReport exr_report = write_exr(image, exr_path, exr);
  std::printf("wrote %s\n", exr_path.c_str());
  if (exr_report.clamped_half_values > 0)
    std::printf("note: %zu values above the half-float range (65504, e.g. the sun disk) were clamped; "
                "set \"output\": {\"half\": false} to keep them\n",
                exr_report.clamped_half_values);
  if (!png_path.empty()) {
    PngWriteOptions png;
    png.exposure_ev = request.output.exposure_ev;
    png.bit_depth = png_bits;
    png.view = request.output.view;
    const PngWriteReport r = write_png(image, png_path, png);
    std::printf("wrote %s (exposure EV100 %.2f)\n", png_path.c_str(), r.exposure_ev);
  }
  const double paths = static_cast<double>(result.counters.paths);
  const Rgb e_rgb = result.error.relative_rms_rgb().value_or(Rgb{0.0, 0.0, 0.0});
  std::printf("time %.2f s, %.0f paths, %.3g paths/s (%.3g per thread), estimated relative RMS error %.4f "
              "(R %.4f, G %.4f, B %.4f), %.4g samples per pixel, stopped by %s\n",
              seconds, paths, paths / seconds, paths / seconds / resolve_thread_count(threads),
              result.estimated_relative_rms, e_rgb.r, e_rgb.g, e_rgb.b, samples, stopped_by.c_str());
  if (result.counters.nonfinite > 0)
    std::printf("warning: %llu non-finite or negative path results were discarded\n",
                static_cast<unsigned long long>(result.counters.nonfinite));
  return 0;
}

int run_render_command(const std::vector<std::string>& args) {
  RenderArgs a;
  if (const std::string err = parse_render_args(args, &a); !err.empty()) {
    std::cerr << "skyfarm-worker render: " << err
              << "\nusage: skyfarm-worker render REQUEST.json -o OUT.exr [--png OUT.png [--png-16bit]] [--threads N]"
                 "\n       [--asset-cache DIR]\n";
    return 2;
  }
  std::string text, error;
  if (!read_input(a.request, &text, &error)) {
    std::cerr << "skyfarm-worker render: " << error << "\n";
    return 1;
  }
  try {
    // Mesh and volume files named by path become asset ids before the request is parsed (request_assets.h).
    std::unique_ptr<AssetDiskCache> disk;  // read only: the farm worker's cache
    std::unique_ptr<LocalMeshSource> meshes;
    std::unique_ptr<LocalVolumeSource> volumes;
    nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (json.is_object() && (json.contains("objects") || json.contains("clouds"))) {
      const char* env_cache = std::getenv("SKYFARM_ASSET_CACHE");
      disk = std::make_unique<AssetDiskCache>(!a.asset_cache.empty() ? a.asset_cache
                                              : env_cache != nullptr && *env_cache != '\0'
                                                  ? std::string(env_cache)
                                                  : default_asset_cache_dir(),
                                              std::numeric_limits<std::size_t>::max());
      const std::filesystem::path base =
          a.request == "-" ? std::filesystem::current_path() : std::filesystem::path(a.request).parent_path();
      meshes = resolve_request_assets(&json, base.string(), disk.get());
      volumes = resolve_request_volumes(&json, base.string(), disk.get());
      text = json.dump();
    }
    const api::RenderRequest request = api::parse_render_request(text);
    return render_to_files(request, a.exr, a.png, a.threads, "render", a.png_bits, meshes.get(), volumes.get());
  } catch (const api::ValidationError& e) {
    std::cerr << a.request << ": invalid request\n" << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-worker render: " << e.what() << "\n";
    return 1;
  }
}

int run_demo_command(const std::vector<std::string>& args) {
  const std::filesystem::path dir = args.empty() ? std::filesystem::path("skyfarm-demo") : std::filesystem::path(args[0]);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::cerr << "skyfarm-worker demo: cannot create " << dir << ": " << ec.message() << "\n";
    return 1;
  }
  try {
    for (const auto& demo : demo_requests()) {
      const api::RenderRequest request = api::parse_render_request(demo.json);
      const int rc = render_to_files(request, (dir / (demo.name + ".exr")).string(),
                                     (dir / (demo.name + ".png")).string(), 0, demo.name);
      if (rc != 0) return rc;
    }
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-worker demo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

int run_probe_command(const std::vector<std::string>& args) {
  std::string path;
  int threads = 0;
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--threads" && i + 1 < args.size()) {
      try {
        threads = std::stoi(args[++i]);
      } catch (const std::exception&) {
        std::cerr << "skyfarm-worker probe: --threads must be an integer\n";
        return 2;
      }
    } else if (path.empty()) {
      path = args[i];
    } else {
      std::cerr << "skyfarm-worker probe: unexpected argument '" << args[i] << "'\n";
      return 2;
    }
  }
  if (path.empty()) path.push_back('-');  // standard input
  std::string text, error;
  if (!read_input(path, &text, &error)) {
    std::cerr << "skyfarm-worker probe: " << error << "\n";
    return 1;
  }
  try {
    const api::ProbeRequest request = api::parse_probe_request(text);
    const nlohmann::json out = api::probe_answer_json(request, answer_probe(api::probe_spec(request), threads));
    std::cout << out.dump(2) << "\n";
    return 0;
  } catch (const api::ValidationError& e) {
    std::cerr << path << ": invalid probe request\n" << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "skyfarm-worker probe: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace skyfarm

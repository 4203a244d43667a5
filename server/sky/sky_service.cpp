#include "server/sky/sky_service.h"

#include "common/sampling/sampler.h"  // fmix64

#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>

#include "api/json_fields.h"
#include "common/atmosphere/atmosphere_builder.h"
#include "common/camera/camera.h"
#include "common/geometry/equal_area.h"
#include "common/image/exr_writer.h"
#include "common/render/parallel.h"
#include "common/sun/solar_spectrum.h"

namespace skyfarm::server {
namespace {

// The visible range of the CIE tables (color.h): XYZ integrates over it.
constexpr double kCieMinNm = 360.0;
constexpr double kCieMaxNm = 830.0;
// Disk samples: at least 64 x 64, and ~256 per map pixel the disk covers, at most 512 x 512.
constexpr int kMinDiskSamples = 64;
constexpr int kMaxDiskSamples = 512;
constexpr double kDiskSamplesPerPixel = 256.0;

void append_hex(std::string& out, std::uint64_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  for (int shift = 60; shift >= 0; shift -= 4) out.push_back(kDigits[(v >> shift) & 0xF]);
}

// L_disk T per bin for a direction inside the disk: the look-up with the disk
// minus the one without (the LUT adds sun_disk_radiance * transmittance).
void disk_radiance(const LutSky& sky, const glm::dvec3& d, std::span<double> with, std::span<double> without) {
  sky.radiance(d, with, true);
  sky.radiance(d, without, false);
  for (std::size_t b = 0; b < with.size(); ++b) with[b] = std::max(0.0, with[b] - without[b]);
}

int disk_sample_side(double disk_pixels) {
  const double n = std::ceil(std::sqrt(std::max(0.0, disk_pixels) * kDiskSamplesPerPixel));
  return static_cast<int>(std::clamp(n, double(kMinDiskSamples), double(kMaxDiskSamples)));
}

std::atomic<std::uint64_t> g_temp_counter{0};

}  // namespace

std::string exact_decimal(double x) {
  if (x == 0.0) x = 0.0;  // -0 -> 0
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

// Eight bytes at a time (an ETag is computed per answer on the hot path):
// two multiply-rotate lanes, then the MurmurHash3 finaliser on both.
std::string text_hash(std::string_view text) {
  constexpr std::uint64_t k1 = 0x9e3779b97f4a7c15ULL, k2 = 0xc2b2ae3d27d4eb4fULL, k3 = 0x165667b19e3779f9ULL;
  auto rotl = [](std::uint64_t x, int r) { return (x << r) | (x >> (64 - r)); };
  std::uint64_t h1 = k1 ^ text.size(), h2 = k2;
  auto mix = [&](std::uint64_t w) {
    h1 = rotl(h1 ^ (w * k2), 31) * k1;
    h2 = (rotl(h2 + w * k3, 29) * k1) ^ h1;
  };
  const char* p = text.data();
  const std::size_t n = text.size();
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    mix(w);
  }
  std::uint64_t tail = 0;
  std::memcpy(&tail, p + i, n - i);
  mix(tail ^ (static_cast<std::uint64_t>(n - i) << 56));
  h1 = fmix64(h1 ^ h2);
  h2 = fmix64(h2 + h1);
  std::string out;
  out.reserve(32);
  append_hex(out, h1);
  append_hex(out, h2);
  return out;
}

namespace {

// The LUT resolution as text (every field: any of them changes the tables).
std::string resolution_text(const LutResolution& r) {
  std::string k;
  for (int v : {r.spectral_bins, r.medium_altitude_samples, r.phase_samples, r.transmittance_mu, r.transmittance_r,
                r.transmittance_steps, r.multiple_scattering_mu_s, r.multiple_scattering_altitude,
                r.multiple_scattering_directions, r.multiple_scattering_steps, r.ground_irradiance_mu_s,
                r.ground_irradiance_directions, r.ground_irradiance_steps, r.sky_view_azimuth, r.sky_view_zenith,
                r.sky_view_steps, r.aerial_azimuth, r.aerial_zenith, r.aerial_slices, r.space_view_steps})
    k += std::to_string(v) + ",";
  k += exact_decimal(r.aerial_max_distance_m);
  return k;
}

}  // namespace

std::string SkyTableParams::key() const {
  std::string k = "lut1|atmosphere=";
  k += api::atmosphere_json(atmosphere).dump();
  k += "|sun=" + exact_decimal(sun_zenith_deg) + "," + exact_decimal(api::canonical_azimuth(sun_azimuth_deg)) + "," +
       exact_decimal(sun_distance_au) + "," + exact_decimal(sun_angular_radius_deg);
  k += "|altitude=" + exact_decimal(altitude_m);
  k += "|nm=" + exact_decimal(min_nm) + "," + exact_decimal(max_nm);
  k += "|res=" + resolution_text(resolution);
  return k;
}

std::string SkyTableParams::atmosphere_key() const {
  std::string k = "lut1|atmosphere=";
  k += api::atmosphere_json(atmosphere).dump();
  k += "|nm=" + exact_decimal(min_nm) + "," + exact_decimal(max_nm);
  k += "|res=" + resolution_text(resolution);
  return k;
}

Xyz SkyTable::xyz(std::span<const double> per_bin) const {
  if (!visible) return {0.0, 0.0, 0.0};
  return visible->xyz(per_bin);
}

namespace {

// The sun as Sun::from_spec makes it: AM0 scaled to the Earth-Sun distance.
Sun table_sun(const SkyTableParams& p) {
  const auto& am0 = am0_irradiance();
  std::vector<double> x(am0.x().begin(), am0.x().end()), y(am0.y().begin(), am0.y().end());
  const double d2 = p.sun_distance_au * p.sun_distance_au;
  for (double& v : y) v /= d2;
  return Sun(p.sun_zenith_deg, p.sun_azimuth_deg, p.sun_angular_radius_deg,
             PiecewiseLinear(std::move(x), std::move(y), PiecewiseLinear::Outside::kZero, "AM0"));
}

std::shared_ptr<const SkyTable> finish_table(const SkyTableParams& p, LutSky sky, Sun sun,
                                             std::chrono::steady_clock::time_point start) {
  std::optional<BinnedSpectrumIntegral> visible;
  const double lo = std::max(kCieMinNm, p.min_nm), hi = std::min(kCieMaxNm, p.max_nm);
  if (lo < hi) visible.emplace(sky.grid(), lo, hi);
  const std::size_t extra = sizeof(SkyTable) + p.key().size() +
                            (visible ? 4 * visible->x_weights().size() * sizeof(double) : 0);
  const std::size_t bytes = sky.memory_bytes() + extra;
  return std::make_shared<SkyTable>(SkyTable{p.key(), std::move(sky), std::move(sun), std::move(visible), bytes,
                                             std::chrono::steady_clock::now() - start});
}

}  // namespace

std::shared_ptr<const SkyTable> build_sky_table(const SkyTableParams& p) {
  const auto start = std::chrono::steady_clock::now();
  const Atmosphere atmosphere = build_atmosphere(p.atmosphere);
  Sun sun = table_sun(p);
  LutSky sky = LutSky::build(atmosphere, sun, p.altitude_m, p.min_nm, p.max_nm, p.resolution);
  if (p.atmosphere.refraction) sky = sky.refracted();
  return finish_table(p, std::move(sky), std::move(sun), start);
}

std::shared_ptr<const SkyTable> sky_table_for_sun(const SkyTable& donor, const SkyTableParams& p) {
  const auto start = std::chrono::steady_clock::now();
  Sun sun = table_sun(p);
  LutSky sky = donor.sky.with_sun(sun, p.altitude_m);
  if (p.atmosphere.refraction) sky = sky.refracted();
  return finish_table(p, std::move(sky), std::move(sun), start);
}

SunDiskSummary sun_disk_summary(const SkyTable& table, int samples) {
  SunDiskSummary s;
  const Sun& sun = table.sun;
  if (sun.is_point()) return s;
  const std::size_t B = static_cast<std::size_t>(table.sky.grid().size());
  std::vector<double> with(B), without(B), sum(B, 0.0);
  const int n = std::max(1, samples);
  double pdf = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto seen = table.sky.disk_sample_direction(sun.sample_direction((i + 0.5) / n, (j + 0.5) / n, &pdf));
      if (!seen) continue;
      disk_radiance(table.sky, seen->direction, with, without);
      for (std::size_t b = 0; b < B; ++b) sum[b] += with[b] * seen->solid_angle_ratio;
    }
  for (double& v : sum) v /= double(n) * double(n);
  s.xyz = table.xyz(sum);
  s.rgb = xyz_to_linear_srgb(s.xyz);
  s.solid_angle_sr = sun.solid_angle_sr();
  s.illuminance_lux = s.xyz.y * s.solid_angle_sr;
  return s;
}

Image render_envmap(const SkyTable& table, int width, EnvmapSun sun_mode, int threads) {
  if (width < 2 || width % 2 != 0) throw std::invalid_argument("envmap: width must be even and >= 2");
  const int height = width / 2;
  CameraSpec spec;
  spec.projection = Projection::kEquirectangular;
  spec.width = width;
  spec.height = height;
  const Camera camera(spec, glm::dvec3(0.0, 0.0, 0.0));
  Image image(width, height);
  const LutSky& sky = table.sky;
  const std::size_t B = static_cast<std::size_t>(sky.grid().size());

  // The sky, one look-up per pixel centre (rows in parallel).
  parallel_for(static_cast<std::size_t>(height), threads, [&](std::size_t row, int) {
    std::vector<double> L(B);
    const int y = static_cast<int>(row);
    Ray ray;
    for (int x = 0; x < width; ++x) {
      if (!camera.generate_ray(x, y, 0.5, 0.5, &ray)) continue;
      sky.radiance(ray.d, L, false);
      image.set_xyz(x, y, table.xyz(L));
    }
  });

  // The disk, splatted (see sky_service.h): exact energy at any resolution.
  const Sun& sun = table.sun;
  if (sun_mode == EnvmapSun::kDisk && !sun.is_point()) {
    double fx = 0.0, fy = 0.0;
    camera.direction_to_film(sun.direction(), &fx, &fy);
    const int cy = std::clamp(static_cast<int>(fy), 0, height - 1);
    const double pixel_sr = camera.pixel_solid_angle(0, cy);
    const int n = disk_sample_side(sun.solid_angle_sr() / std::max(pixel_sr, 1e-300));
    const double weight = sun.solid_angle_sr() / (double(n) * double(n));  // sr per sample
    std::vector<double> with(B), without(B);
    std::unordered_map<std::uint64_t, std::vector<double>> splats;  // pixel -> sum of L T dOmega per bin
    double pdf = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        // With refraction each sample shows at its apparent place, its solid
        // angle scaled (LutSky::disk_sample_direction).
        const auto seen = sky.disk_sample_direction(sun.sample_direction((i + 0.5) / n, (j + 0.5) / n, &pdf));
        if (!seen) continue;
        const glm::dvec3 d = seen->direction;
        if (!camera.direction_to_film(d, &fx, &fy)) continue;
        const int px = std::clamp(static_cast<int>(fx), 0, width - 1);
        const int py = std::clamp(static_cast<int>(fy), 0, height - 1);
        disk_radiance(sky, d, with, without);
        auto& acc = splats[static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(width) +
                           static_cast<std::uint64_t>(px)];
        if (acc.empty()) acc.assign(B, 0.0);
        for (std::size_t b = 0; b < B; ++b) acc[b] += with[b] * weight * seen->solid_angle_ratio;
      }
    for (auto& [index, acc] : splats) {
      const int px = static_cast<int>(index % static_cast<std::uint64_t>(width));
      const int py = static_cast<int>(index / static_cast<std::uint64_t>(width));
      const double omega = camera.pixel_solid_angle(px, py);
      if (!(omega > 0.0)) continue;
      for (double& v : acc) v /= omega;
      const Rgb disk = xyz_to_linear_srgb(table.xyz(acc));
      const auto old = image.rgb(px, py);
      image.set_rgb(px, py, Rgb{old[0] + disk.r, old[1] + disk.g, old[2] + disk.b});
    }
  }
  return image;
}

Image render_envmap_equal_area(const SkyTable& table, int width, EnvmapSun sun_mode, int threads) {
  if (width < 2 || width % 2 != 0) throw std::invalid_argument("envmap: width must be even and >= 2");
  const int n = width;
  Image image(n, n);
  const LutSky& sky = table.sky;
  const std::size_t B = static_cast<std::size_t>(sky.grid().size());
  const double inv_n = 1.0 / double(n);

  // The sky: the mean of k x k stratified look-ups per pixel (each stratum
  // holds the same solid angle, so the plain mean is the mean over the pixel).
  constexpr int k = kEqualAreaSkySamples;
  parallel_for(static_cast<std::size_t>(n), threads, [&](std::size_t row, int) {
    std::vector<double> L(B), sum(B);
    const int y = static_cast<int>(row);
    for (int x = 0; x < n; ++x) {
      std::fill(sum.begin(), sum.end(), 0.0);
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j) {
          const glm::dvec2 p((x + (i + 0.5) / k) * inv_n, (y + (j + 0.5) / k) * inv_n);
          sky.radiance(equal_area_square_to_sphere(p), L, false);
          for (std::size_t b = 0; b < B; ++b) sum[b] += L[b];
        }
      for (double& v : sum) v /= double(k) * double(k);
      image.set_xyz(x, y, table.xyz(sum));
    }
  });

  // The disk, splatted as in render_envmap: exact energy at any resolution.
  const Sun& sun = table.sun;
  if (sun_mode == EnvmapSun::kDisk && !sun.is_point()) {
    const double pixel_sr = equal_area_pixel_solid_angle(n);
    const int m = disk_sample_side(sun.solid_angle_sr() / pixel_sr);
    const double weight = sun.solid_angle_sr() / (double(m) * double(m));  // sr per sample
    std::vector<double> with(B), without(B);
    std::unordered_map<std::uint64_t, std::vector<double>> splats;  // pixel -> sum of L T dOmega per bin
    double pdf = 0.0;
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        const auto seen = sky.disk_sample_direction(sun.sample_direction((i + 0.5) / m, (j + 0.5) / m, &pdf));
        if (!seen) continue;
        const glm::dvec3 d = seen->direction;
        const glm::dvec2 p = equal_area_sphere_to_square(d);
        const int px = std::clamp(static_cast<int>(p.x * n), 0, n - 1);
        const int py = std::clamp(static_cast<int>(p.y * n), 0, n - 1);
        disk_radiance(sky, d, with, without);
        auto& acc = splats[static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(n) +
                           static_cast<std::uint64_t>(px)];
        if (acc.empty()) acc.assign(B, 0.0);
        for (std::size_t b = 0; b < B; ++b) acc[b] += with[b] * weight * seen->solid_angle_ratio;
      }
    for (auto& [index, acc] : splats) {
      const int px = static_cast<int>(index % static_cast<std::uint64_t>(n));
      const int py = static_cast<int>(index / static_cast<std::uint64_t>(n));
      for (double& v : acc) v /= pixel_sr;
      const Rgb disk = xyz_to_linear_srgb(table.xyz(acc));
      const auto old = image.rgb(px, py);
      image.set_rgb(px, py, Rgb{old[0] + disk.r, old[1] + disk.g, old[2] + disk.b});
    }
  }
  return image;
}

std::string encode_envmap_exr(const Image& image, bool latlong, ColorSpace color_space, RadiometricUnits units) {
  namespace fs = std::filesystem;
  const fs::path path = fs::temp_directory_path() / ("skyfarm-envmap-" + std::to_string(::getpid()) + "-" +
                                                      std::to_string(g_temp_counter.fetch_add(1)) + ".exr");
  ExrWriteOptions options;
  options.half = false;  // the disk is ~1e9 cd/m^2: HALF would clamp it at 65504
  options.spectral_channels = false;
  options.error_layer = false;
  // PIZ: lossless, and on these maps both smaller and faster than ZIP (2048 x
  // 1024: 8.4 MB in 0.33 s against 10.7 MB in 0.41 s; OpenEXR compresses on
  // one thread here).
  options.compression = ExrCompression::kPiz;
  options.latlong_envmap = latlong;
  options.color_space = color_space;
  options.units = units;  // relative: the map's own automatic exposure
  struct Remove {
    fs::path p;
    ~Remove() {
      std::error_code ec;
      fs::remove(p, ec);
    }
  } remove{path};
  write_exr(image, path, options);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("envmap: cannot read back " + path.string());
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw std::runtime_error("envmap: cannot read back " + path.string());
  return bytes;
}

// --- SkyService ------------------------------------------------------------------

SkyService::SkyService(SkyServiceOptions options)
    : options_(std::move(options)),
      tables_(options_.table_cache_bytes),
      envmaps_(options_.envmap_cache_bytes) {}

std::shared_ptr<const SkyTable> SkyService::table(SkyTableParams params) {
  const int bins = params.resolution.spectral_bins;
  params.resolution = options_.resolution;
  params.resolution.spectral_bins = bins;
  const std::string key = params.key();
  return tables_.get(
      key,
      [&] {
        auto t = make_table(params);
        build_nanoseconds_.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(t->build_time).count(),
                                     std::memory_order_relaxed);
        return t;
      },
      [](const SkyTable& t) { return t.bytes; });
}

std::shared_ptr<const SkyTable> SkyService::full_build(const SkyTableParams& params) {
  auto t = options_.table_builder ? options_.table_builder(params) : build_sky_table(params);
  if (!t) throw std::runtime_error("sky table builder returned nothing");
  return t;
}

std::shared_ptr<const SkyTable> SkyService::make_table(const SkyTableParams& params) {
  if (!options_.reuse_atmosphere_tables) return full_build(params);
  const std::string atmosphere = params.atmosphere_key();
  std::shared_ptr<const SkyTable> donor;
  std::shared_future<std::shared_ptr<const SkyTable>> pending;
  std::promise<std::shared_ptr<const SkyTable>> building;
  {
    std::lock_guard lock(atmospheres_mu_);
    if (const auto it = atmosphere_donors_.find(atmosphere); it != atmosphere_donors_.end()) donor = it->second.lock();
    if (!donor) {
      if (const auto it = atmosphere_builds_.find(atmosphere); it != atmosphere_builds_.end())
        pending = it->second;
      else
        atmosphere_builds_.emplace(atmosphere, building.get_future().share());
    }
  }
  if (pending.valid()) {  // another sun of this atmosphere is being built in full: wait, then add ours
    try {
      donor = pending.get();
    } catch (...) {
      donor = nullptr;  // that build failed: ours is a full build (not shared)
    }
    if (!donor) return full_build(params);
  }
  if (donor) {
    auto t = sky_table_for_sun(*donor, params);
    sun_only_builds_.fetch_add(1, std::memory_order_relaxed);
    std::lock_guard lock(atmospheres_mu_);
    atmosphere_donors_[atmosphere] = t;
    return t;
  }
  // We build this atmosphere's tables; later misses take theirs from ours.
  std::shared_ptr<const SkyTable> t;
  try {
    t = full_build(params);
  } catch (...) {
    {
      std::lock_guard lock(atmospheres_mu_);
      atmosphere_builds_.erase(atmosphere);
    }
    building.set_exception(std::current_exception());
    throw;
  }
  {
    std::lock_guard lock(atmospheres_mu_);
    atmosphere_builds_.erase(atmosphere);
    std::erase_if(atmosphere_donors_, [](const auto& entry) { return entry.second.expired(); });
    atmosphere_donors_[atmosphere] = t;
  }
  building.set_value(t);
  return t;
}

std::shared_ptr<const EnvmapFile> SkyService::envmap(const std::string& key, const std::function<std::string()>& make) {
  return envmaps_.get(
      key,
      [&] {
        // At most max_concurrent_envmaps distinct maps at once: each holds a
        // width x width/2 float image and its EXR in memory.
        {
          std::unique_lock lock(render_mu_);
          render_cv_.wait(lock, [&] { return rendering_ < std::max(1, options_.max_concurrent_envmaps); });
          ++rendering_;
        }
        struct Release {
          SkyService* s;
          ~Release() {
            {
              std::lock_guard lock(s->render_mu_);
              --s->rendering_;
            }
            s->render_cv_.notify_one();
          }
        } release{this};
        auto file = std::make_shared<EnvmapFile>();
        file->bytes = make();
        file->etag = text_hash(file->bytes);
        file->etag.insert(file->etag.begin(), '"');
        file->etag.push_back('"');
        return std::shared_ptr<const EnvmapFile>(std::move(file));
      },
      [](const EnvmapFile& f) { return f.bytes.size() + f.etag.size() + sizeof(EnvmapFile); });
}

SkyCacheStats SkyService::stats() const {
  const auto t = tables_.stats();
  const auto e = envmaps_.stats();
  SkyCacheStats s;
  s.table_hits = t.hits;
  s.table_misses = t.misses;
  s.table_waits = t.waits;
  s.table_builds = t.builds;
  s.table_build_failures = t.failures;
  s.table_evictions = t.evictions;
  s.table_bytes = t.bytes;
  s.table_entries = t.entries;
  s.table_capacity_bytes = t.capacity;
  s.table_build_seconds = 1e-9 * static_cast<double>(build_nanoseconds_.load(std::memory_order_relaxed));
  s.table_sun_only_builds = sun_only_builds_.load(std::memory_order_relaxed);
  s.envmap_hits = e.hits;
  s.envmap_misses = e.misses;
  s.envmap_waits = e.waits;
  s.envmap_builds = e.builds;
  s.envmap_build_failures = e.failures;
  s.envmap_evictions = e.evictions;
  s.envmap_bytes = e.bytes;
  s.envmap_entries = e.entries;
  s.envmap_capacity_bytes = e.capacity;
  return s;
}

}  // namespace skyfarm::server

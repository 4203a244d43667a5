// The sky look-up service behind GET /v1/sky and GET /v1/sky/envmap.exr:
// built LUT skies (common/lut/lut_sky.h) kept in memory, and
// the environment maps made from them.
//
// Two caches, both LRU, both bounded in BYTES, both thread-safe:
//   tables   key: SkyTableParams::key() (canonical atmosphere JSON, sun
//            zenith/azimuth/Earth-Sun distance/angular radius as exact
//            decimal text, observer altitude, wavelength range, the whole
//            LUT resolution); size: LutSky::memory_bytes() (+ the small
//            per-entry extras); default bound 256 MiB
//   envmaps  key: the full canonical parameter set of the request (the
//            caller's text); size: the EXR's bytes; default bound 128 MiB
// A table for a new sun (or observer altitude) of an atmosphere whose tables
// are alive (cached, or in use) is made by LutSky::with_sun from them: only
// the sun-dependent sky-view and aerial-perspective tables are built (3.7-5x
// less CPU than a full build in scripts/bench-sky.sh's cold sweep, whose
// figures are in the README), and every look-up equals a full build's
// bit for bit (the same code builds the same tables).  Such tables share the
// atmosphere's tables; each entry still counts them in its bytes, so the
// bound is an upper bound on the memory held (reached later than it could
// be).  Concurrent misses of one new atmosphere wait for one full build and
// then each adds its sun.  Keyed by SkyTableParams::atmosphere_key().
// Both are "single flight": concurrent callers of one missing key wait on
// one shared future, so a table (or a map) is built once however many ask
// for it at the same time.  A build that throws is not cached: every waiter
// gets its exception and the next call tries again.  No lock is held while
// building; an entry larger than the whole bound is handed back but not kept.
//
// The hot path of a look-up (table present) is: one key string, one hash
// map probe under a mutex, a list splice; the LutSky itself is immutable
// and shared (std::shared_ptr), so look-ups run in parallel without a lock.
//
// Environment maps (render_envmap): the camera of an equirectangular render
// (common/camera/camera.h, yaw = pitch = roll = 0: centre = north, right =
// east, top = zenith), one LUT look-up per pixel centre for the sky, and the
// sun disk splatted: N stratified directions uniformly over the disk, each
// carrying L_disk T (Omega_disk / N), added to the pixel it falls in and
// divided by that pixel's solid angle, so the disk's energy in the map is
// exact whatever the resolution (a disk smaller than a pixel included).
// Equal-area maps (render_envmap_equal_area): a width x width square in the
// octahedral mapping of common/geometry/equal_area.h, the layout of pbrt-v4's
// `imagemap` infinite light, read in the observer frame (x east, y north, z
// zenith: the zenith at the centre, north below it, east to its right, the
// nadir at the corners).  Every pixel holds 4 pi / width^2 sr, so each holds
// the MEAN radiance over its solid angle: the sky is averaged over
// kEqualAreaSkySamples^2 stratified directions per pixel (uniform in the
// square is uniform in solid angle), and the disk is splatted as above.
// Values: linear Rec.709 (D65) in absolute units, Y in cd/m^2, as the
// renders' Image::set_xyz.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include "common/atmosphere/atmosphere_spec.h"
#include "common/film/image.h"
#include "common/image/color_management.h"
#include "common/lut/lut_sky.h"
#include "common/lut/spectral_grid.h"
#include "common/spectrum/color.h"
#include "common/sun/sun.h"

namespace skyfarm::server {

// Exact decimal text of a double (shortest text that reads back to the same
// value; -0 as 0): the form every number takes in the cache keys.
std::string exact_decimal(double x);

// 16-hex-digit hash of a text (two 64-bit MurmurHash3 finaliser chains), for
// strong entity tags: quote it yourself.
std::string text_hash(std::string_view text);

// What one table is built from.
struct SkyTableParams {
  AtmosphereSpec atmosphere;
  double sun_zenith_deg = 0.0;
  double sun_azimuth_deg = 0.0;    // clockwise from north
  double sun_distance_au = 1.0;    // AM0 / R^2 (1 when no time was given)
  double sun_angular_radius_deg = 0.2666;
  double altitude_m = 0.0;         // observer above the ground
  double min_nm = 360.0, max_nm = 830.0;
  LutResolution resolution;        // spectral_bins included

  // The cache key (canonical text, see the top of this file).
  std::string key() const;
  // What the sun-independent tables depend on: the key without the sun and
  // the observer altitude.
  std::string atmosphere_key() const;
};

// A built sky: the LUT, its sun, and the weights that turn its binned
// spectra into absolute XYZ over [max(360, min), min(830, max)] (none when
// the range does not reach the visible: XYZ is then 0).
struct SkyTable {
  std::string key;
  LutSky sky;
  Sun sun;
  std::optional<BinnedSpectrumIntegral> visible;
  std::size_t bytes = 0;
  std::chrono::duration<double> build_time{};

  // XYZ of a binned spectrum (cd/m^2 scale).
  Xyz xyz(std::span<const double> per_bin) const;
};

// Builds a table (no caching): the atmosphere from its spec, the sun (AM0 /
// R^2 at the given angles), LutSky::build.  Throws what they throw.
std::shared_ptr<const SkyTable> build_sky_table(const SkyTableParams& params);
// The same table from `donor`'s atmosphere tables (LutSky::with_sun): donor
// must have params' atmosphere_key().  Equal to build_sky_table(params).
std::shared_ptr<const SkyTable> sky_table_for_sun(const SkyTable& donor, const SkyTableParams& params);

enum class EnvmapSun { kDisk, kNone, kSeparate };

// The disk as seen from the observer: its radiance averaged over the disk
// (transmittance included), as XYZ and linear Rec.709 (cd/m^2), its solid
// angle, and the normal illuminance it gives (Y_mean * Omega, lux).
struct SunDiskSummary {
  Xyz xyz{0, 0, 0};
  Rgb rgb{0, 0, 0};
  double solid_angle_sr = 0.0;
  double illuminance_lux = 0.0;
};

// The mean over the disk of L_disk T, per bin, from `samples` x `samples`
// stratified directions (what render_envmap splats).
SunDiskSummary sun_disk_summary(const SkyTable& table, int samples = 64);

// A width x width/2 lat-long map of `table` (layout above); `sun` says whether
// the disk is in the pixels.  `threads` <= 0: all cores.
Image render_envmap(const SkyTable& table, int width, EnvmapSun sun, int threads = 0);

// Strata per side of the sky's samples in each equal-area pixel.
inline constexpr int kEqualAreaSkySamples = 2;

// A width x width equal-area map of `table` (layout above).
Image render_envmap_equal_area(const SkyTable& table, int width, EnvmapSun sun, int threads = 0);

// The image as a FLOAT, PIZ-compressed (lossless) OpenEXR, as bytes (written
// through a temporary file); `latlong`: with the standard `envmap` attribute
// LATLONG (OpenEXR has no name for the equal-area layout); R, G, B in the
// colour space and units asked for (exr_writer.h).
std::string encode_envmap_exr(const Image& image, bool latlong = true,
                              ColorSpace color_space = ColorSpace::kLinRec709,
                              RadiometricUnits units = RadiometricUnits::kCdM2);

// --- The caches ----------------------------------------------------------------

struct SkyServiceOptions {
  std::size_t table_cache_bytes = std::size_t{256} << 20;
  std::size_t envmap_cache_bytes = std::size_t{128} << 20;
  LutResolution resolution;   // every field but spectral_bins; bins come from the request
  int envmap_threads = 0;     // per map; <= 0: all cores
  int max_concurrent_envmaps = 2;  // distinct maps rendered at once (memory bound); others wait
  // Replaces build_sky_table (tests count or fail builds with it).
  std::function<std::shared_ptr<const SkyTable>(const SkyTableParams&)> table_builder;
  // Make tables for new suns from cached atmosphere tables (false: every
  // table is a full build, as before; benchmarks compare the two).
  bool reuse_atmosphere_tables = true;
};

// Figures for /metrics (skyfarm_sky_cache_*).
struct SkyCacheStats {
  std::uint64_t table_hits = 0, table_misses = 0, table_waits = 0, table_builds = 0, table_build_failures = 0,
                table_evictions = 0;
  std::size_t table_bytes = 0, table_entries = 0, table_capacity_bytes = 0;
  double table_build_seconds = 0.0;  // total
  std::uint64_t table_sun_only_builds = 0;  // of table_builds: made by with_sun from cached atmosphere tables
  std::uint64_t envmap_hits = 0, envmap_misses = 0, envmap_waits = 0, envmap_builds = 0,
                envmap_build_failures = 0, envmap_evictions = 0;
  std::size_t envmap_bytes = 0, envmap_entries = 0, envmap_capacity_bytes = 0;
};

// A single-flight LRU bounded in bytes (the two caches above).
template <class V>
class SingleFlightLru {
 public:
  using Ptr = std::shared_ptr<const V>;
  struct Stats {
    std::uint64_t hits = 0, misses = 0, waits = 0, builds = 0, failures = 0, evictions = 0;
    std::size_t bytes = 0, entries = 0, capacity = 0;
  };

  explicit SingleFlightLru(std::size_t capacity_bytes) : capacity_(capacity_bytes) {}

  // The cached value, or nullptr (counts a hit when found, nothing otherwise).
  Ptr find(const std::string& key) {
    std::lock_guard lock(mu_);
    const auto it = index_.find(key);
    if (it == index_.end()) return nullptr;
    lru_.splice(lru_.begin(), lru_, it->second);
    ++hits_;
    return it->second->value;
  }

  // The cached value, or the one `make` builds (once for all concurrent
  // callers of `key`); `size` gives its bytes.  Exceptions of `make` reach
  // every caller waiting for that build and nothing is cached.
  template <class Make, class Size>
  Ptr get(const std::string& key, Make&& make, Size&& size) {
    std::promise<Ptr> promise;
    std::shared_future<Ptr> pending;
    {
      std::unique_lock lock(mu_);
      if (const auto it = index_.find(key); it != index_.end()) {
        lru_.splice(lru_.begin(), lru_, it->second);
        ++hits_;
        return it->second->value;
      }
      if (const auto it = building_.find(key); it != building_.end()) {
        ++waits_;
        pending = it->second;
      } else {
        ++misses_;
        building_.emplace(key, promise.get_future().share());
      }
    }
    if (pending.valid()) return pending.get();  // rethrows a failed build
    Ptr value;
    try {
      value = make();
    } catch (...) {
      {
        std::lock_guard lock(mu_);
        building_.erase(key);
        ++failures_;
      }
      promise.set_exception(std::current_exception());
      throw;
    }
    const std::size_t bytes = size(*value);
    {
      std::lock_guard lock(mu_);
      building_.erase(key);
      ++builds_;
      insert(key, value, bytes);
    }
    promise.set_value(value);
    return value;
  }

  Stats stats() const {
    std::lock_guard lock(mu_);
    return {hits_, misses_, waits_, builds_, failures_, evictions_, bytes_, lru_.size(), capacity_};
  }

 private:
  struct Entry {
    std::string key;
    Ptr value;
    std::size_t bytes;
  };

  // Under mu_.  Entries larger than the whole cache are not kept.
  void insert(const std::string& key, const Ptr& value, std::size_t bytes) {
    if (bytes > capacity_) return;
    if (const auto it = index_.find(key); it != index_.end()) {  // cannot happen (single flight), but be safe
      bytes_ -= it->second->bytes;
      lru_.erase(it->second);
      index_.erase(it);
    }
    while (!lru_.empty() && bytes_ + bytes > capacity_) {
      bytes_ -= lru_.back().bytes;
      index_.erase(lru_.back().key);
      lru_.pop_back();
      ++evictions_;
    }
    lru_.push_front(Entry{key, value, bytes});
    index_.emplace(key, lru_.begin());
    bytes_ += bytes;
  }

  mutable std::mutex mu_;
  std::list<Entry> lru_;  // most recently used first
  std::unordered_map<std::string, typename std::list<Entry>::iterator> index_;
  std::unordered_map<std::string, std::shared_future<Ptr>> building_;
  const std::size_t capacity_;
  std::size_t bytes_ = 0;
  std::uint64_t hits_ = 0, misses_ = 0, waits_ = 0, builds_ = 0, failures_ = 0, evictions_ = 0;
};

// A finished environment map: the EXR bytes and their strong ETag.
struct EnvmapFile {
  std::string bytes;
  std::string etag;  // quoted
};

class SkyService {
 public:
  explicit SkyService(SkyServiceOptions options = {});
  SkyService(const SkyService&) = delete;
  SkyService& operator=(const SkyService&) = delete;

  const SkyServiceOptions& options() const { return options_; }

  // The table for `params` (params.resolution is replaced by the service's,
  // keeping params.resolution.spectral_bins).
  std::shared_ptr<const SkyTable> table(SkyTableParams params);

  // The env map cached under `key`, or the one `make` encodes (once for all
  // concurrent callers), at most max_concurrent_envmaps made at a time.
  std::shared_ptr<const EnvmapFile> envmap(const std::string& key, const std::function<std::string()>& make);

  SkyCacheStats stats() const;

 private:
  // A table missing from the cache: for its sun from a live table of its
  // atmosphere, else a full build (one at a time per atmosphere).
  std::shared_ptr<const SkyTable> make_table(const SkyTableParams& params);
  std::shared_ptr<const SkyTable> full_build(const SkyTableParams& params);

  SkyServiceOptions options_;
  SingleFlightLru<SkyTable> tables_;
  SingleFlightLru<EnvmapFile> envmaps_;
  std::atomic<std::int64_t> build_nanoseconds_{0};
  std::atomic<std::uint64_t> sun_only_builds_{0};
  std::mutex atmospheres_mu_;
  // atmosphere_key -> the latest table of that atmosphere (alive while cached or in use).
  std::unordered_map<std::string, std::weak_ptr<const SkyTable>> atmosphere_donors_;
  // atmosphere_key -> its full build in progress.
  std::unordered_map<std::string, std::shared_future<std::shared_ptr<const SkyTable>>> atmosphere_builds_;
  std::mutex render_mu_;
  std::condition_variable render_cv_;
  int rendering_ = 0;
};

}  // namespace skyfarm::server

// SkyService (server/sky/sky_service.h): canonical keys, the single-flight LRU
// (one build for concurrent callers, failed builds not cached, eviction by
// bytes), and what the tables and env maps contain (a blue zenith, the sun
// disk's pixels brightest and its energy exact).  Real LUT skies at a coarse
// resolution keep the suite fast.
#include "server/sky/sky_service.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "common/camera/camera.h"
#include "common/geometry/equal_area.h"
#include "common/image/exr_writer.h"
#include "common/lut/fibonacci_directions.h"
#include "tests/support/coarse_lut.h"

namespace skyfarm::server {
namespace {

using namespace std::chrono_literals;

// A coarse LUT: ~10-50 ms to build, good enough for colours and layout.
LutResolution coarse() { return coarse_lut_resolution(8); }

SkyTableParams params(double sun_zenith = 30.0, double sun_azimuth = 180.0) {
  SkyTableParams p;
  p.sun_zenith_deg = sun_zenith;
  p.sun_azimuth_deg = sun_azimuth;
  p.resolution = coarse();
  return p;
}

SkyServiceOptions coarse_options() {
  SkyServiceOptions o;
  o.resolution = coarse();
  return o;
}

glm::dvec3 direction(double zenith_deg, double azimuth_deg) {
  const double z = zenith_deg * M_PI / 180.0, a = azimuth_deg * M_PI / 180.0;
  return {std::sin(z) * std::sin(a), std::sin(z) * std::cos(a), std::cos(z)};
}

TEST(SkyServiceKey, IsCanonicalAndExact) {
  SkyTableParams a = params(), b = params();
  EXPECT_EQ(a.key(), b.key());
  b.sun_azimuth_deg = 360.0;
  a.sun_azimuth_deg = 0.0;
  EXPECT_EQ(a.key(), b.key()) << "azimuth 360 is azimuth 0";
  b = a;
  b.sun_zenith_deg = 0.1 + 0.2;  // 0.30000000000000004
  a.sun_zenith_deg = 0.3;
  EXPECT_NE(a.key(), b.key()) << "exact decimal text, no rounding";
  b = a;
  b.altitude_m = 1.0;
  EXPECT_NE(a.key(), b.key());
  b = a;
  b.atmosphere.ozone_du = 301.0;
  EXPECT_NE(a.key(), b.key());
  b = a;
  b.resolution.sky_view_steps += 1;
  EXPECT_NE(a.key(), b.key());
  b = a;
  b.sun_distance_au = 1.0167;
  EXPECT_NE(a.key(), b.key());
  EXPECT_EQ(exact_decimal(-0.0), "0");
  EXPECT_EQ(exact_decimal(0.1), "0.1");
  EXPECT_EQ(text_hash("a"), text_hash("a"));
  EXPECT_NE(text_hash("a"), text_hash("b"));
  EXPECT_EQ(text_hash("").size(), 32u);
}

TEST(SkyServiceLru, EvictsLeastRecentlyUsedByBytes) {
  SingleFlightLru<std::string> lru(100);
  auto make = [](std::string v) { return [v] { return std::make_shared<const std::string>(v); }; };
  auto size = [](const std::string& s) { return s.size(); };
  lru.get("a", make(std::string(40, 'a')), size);
  lru.get("b", make(std::string(40, 'b')), size);
  EXPECT_EQ(lru.stats().bytes, 80u);
  EXPECT_EQ(*lru.get("a", make("never"), size), std::string(40, 'a'));  // a is now the most recent
  lru.get("c", make(std::string(40, 'c')), size);                       // 120 > 100: evict b
  auto s = lru.stats();
  EXPECT_EQ(s.entries, 2u);
  EXPECT_EQ(s.bytes, 80u);
  EXPECT_EQ(s.evictions, 1u);
  EXPECT_EQ(s.hits, 1u);
  EXPECT_EQ(s.misses, 3u);
  EXPECT_EQ(lru.find("b"), nullptr);
  EXPECT_NE(lru.find("a"), nullptr);
  EXPECT_NE(lru.find("c"), nullptr);
  // Larger than the whole cache: answered, not kept, nothing evicted for it.
  EXPECT_EQ(lru.get("huge", make(std::string(101, 'h')), size)->size(), 101u);
  s = lru.stats();
  EXPECT_EQ(s.entries, 2u);
  EXPECT_EQ(s.evictions, 1u);
  EXPECT_EQ(lru.find("huge"), nullptr);
}

TEST(SkyServiceCache, ConcurrentRequestsForOneKeyBuildOnce) {
  std::atomic<int> builds{0};
  SkyServiceOptions o = coarse_options();
  o.table_builder = [&](const SkyTableParams& p) {
    ++builds;
    std::this_thread::sleep_for(50ms);  // every caller arrives while it builds
    return build_sky_table(p);
  };
  SkyService service(o);
  constexpr int kThreads = 12;
  std::barrier start(kThreads);
  std::vector<std::shared_ptr<const SkyTable>> got(kThreads);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&, i] {
      start.arrive_and_wait();
      got[static_cast<std::size_t>(i)] = service.table(params());
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(builds.load(), 1);
  for (const auto& t : got) EXPECT_EQ(t.get(), got[0].get());
  const SkyCacheStats s = service.stats();
  EXPECT_EQ(s.table_builds, 1u);
  EXPECT_EQ(s.table_misses, 1u);
  EXPECT_EQ(s.table_waits + s.table_hits, static_cast<std::uint64_t>(kThreads - 1));
  EXPECT_EQ(s.table_entries, 1u);
  EXPECT_EQ(s.table_bytes, got[0]->bytes);
  EXPECT_GT(s.table_bytes, 0u);
  EXPECT_GT(s.table_build_seconds, 0.0);
  // Later calls are hits on the same table.
  EXPECT_EQ(service.table(params()).get(), got[0].get());
  EXPECT_EQ(service.stats().table_builds, 1u);
}

TEST(SkyServiceCache, FailedBuildsAreNotCached) {
  std::atomic<int> calls{0};
  SkyServiceOptions o = coarse_options();
  o.table_builder = [&](const SkyTableParams& p) -> std::shared_ptr<const SkyTable> {
    if (calls++ == 0) {
      std::this_thread::sleep_for(30ms);
      throw std::runtime_error("table build failed");
    }
    return build_sky_table(p);
  };
  SkyService service(o);
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i)
    threads.emplace_back([&] {
      try {
        service.table(params());
      } catch (const std::runtime_error&) {
        ++failures;
      }
    });
  for (auto& t : threads) t.join();
  // Whoever waited on the failed build got its exception; a caller arriving
  // after the failure started a new build (and succeeded).
  EXPECT_GE(failures.load(), 1);
  auto s = service.stats();
  EXPECT_EQ(s.table_build_failures, 1u);
  EXPECT_NE(service.table(params()), nullptr);
  s = service.stats();
  EXPECT_EQ(s.table_entries, 1u);
  EXPECT_EQ(s.table_builds, 1u);
}

TEST(SkyServiceCache, TablesAreEvictedByBytes) {
  const std::size_t one = build_sky_table(params())->bytes;
  SkyServiceOptions o = coarse_options();
  o.table_cache_bytes = one + one / 2;  // room for one table
  SkyService service(o);
  auto first = service.table(params(30.0));
  auto second = service.table(params(40.0));
  auto s = service.stats();
  EXPECT_EQ(s.table_entries, 1u);
  EXPECT_EQ(s.table_evictions, 1u);
  EXPECT_LE(s.table_bytes, o.table_cache_bytes);
  service.table(params(40.0));
  EXPECT_EQ(service.stats().table_hits, 1u);
  service.table(params(30.0));  // evicted: built again
  s = service.stats();
  EXPECT_EQ(s.table_builds, 3u);
  EXPECT_EQ(s.table_evictions, 2u);
}

// A new sun (and altitude) of a cached atmosphere: only the sun-dependent
// tables are built (LutSky::with_sun), and every look-up equals a full
// build's bit for bit.
TEST(SkyServiceCache, NewSunsReuseTheAtmosphereTablesBitForBit) {
  SkyService service(coarse_options());
  const auto noon = service.table(params(30.0, 180.0));
  SkyTableParams evening = params(70.0, 250.0);
  evening.altitude_m = 1500.0;
  evening.sun_distance_au = 1.0167;
  const auto reused = service.table(evening);
  SkyCacheStats s = service.stats();
  EXPECT_EQ(s.table_builds, 2u);
  EXPECT_EQ(s.table_sun_only_builds, 1u);
  const auto fresh = build_sky_table(evening);
  EXPECT_EQ(reused->key, fresh->key);
  EXPECT_EQ(reused->bytes, fresh->bytes) << "shared tables are counted in every entry";
  const std::size_t B = static_cast<std::size_t>(fresh->sky.grid().size());
  std::vector<double> a(B), b(B);
  for (const glm::dvec3& d : lut::fibonacci_sphere(64)) {
    for (bool disk : {false, true}) {
      reused->sky.radiance(d, a, disk);
      fresh->sky.radiance(d, b, disk);
      for (std::size_t k = 0; k < B; ++k) ASSERT_EQ(a[k], b[k]) << "bin " << k;
    }
    EXPECT_EQ(reused->xyz(a).y, fresh->xyz(b).y);
  }
  // Another atmosphere is a full build; so is everything with reuse off.
  SkyTableParams hazy = params(30.0, 180.0);
  hazy.atmosphere.ozone_du = 350.0;
  service.table(hazy);
  EXPECT_EQ(service.stats().table_sun_only_builds, 1u);
  SkyServiceOptions off = coarse_options();
  off.reuse_atmosphere_tables = false;
  SkyService before(off);
  before.table(params(30.0, 180.0));
  before.table(params(70.0, 250.0));
  EXPECT_EQ(before.stats().table_sun_only_builds, 0u);
}

// Many suns of a new atmosphere at once: one full build, the rest wait for
// it and add their sun.
TEST(SkyServiceCache, ConcurrentSunsOfANewAtmosphereBuildItOnce) {
  std::atomic<int> full_builds{0};
  SkyServiceOptions o = coarse_options();
  o.table_builder = [&](const SkyTableParams& p) {
    ++full_builds;
    std::this_thread::sleep_for(50ms);  // the others arrive while it builds
    return build_sky_table(p);
  };
  SkyService service(o);
  constexpr int kThreads = 6;
  std::barrier start(kThreads);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&, i] {
      start.arrive_and_wait();
      service.table(params(10.0 + 10.0 * i, 90.0));
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(full_builds.load(), 1);
  const SkyCacheStats s = service.stats();
  EXPECT_EQ(s.table_builds, static_cast<std::uint64_t>(kThreads));
  EXPECT_EQ(s.table_sun_only_builds, static_cast<std::uint64_t>(kThreads - 1));
}

TEST(SkyServiceTable, ZenithAtMiddayIsBlueAndPositive) {
  const auto table = build_sky_table(params(25.0, 180.0));
  std::vector<double> L(static_cast<std::size_t>(table->sky.grid().size()));
  table->sky.radiance(direction(0.0, 0.0), L, true);
  for (double v : L) EXPECT_GT(v, 0.0);
  const Xyz xyz = table->xyz(L);
  const Rgb rgb = xyz_to_linear_srgb(xyz);
  EXPECT_GT(xyz.y, 1000.0) << "a clear midday zenith is several kcd/m^2";
  EXPECT_LT(xyz.y, 20000.0);
  EXPECT_GT(rgb.b, rgb.r);
  EXPECT_GT(rgb.r, 0.0);
}

TEST(SkyServiceEnvmap, SunPixelsAreBrightestAndTheDiskEnergyIsExact) {
  const auto table = build_sky_table(params(60.0, 90.0));
  for (int width : {64, 512}) {
    const Image with = render_envmap(*table, width, EnvmapSun::kDisk, 2);
    const Image without = render_envmap(*table, width, EnvmapSun::kNone, 2);
    ASSERT_EQ(with.width(), width);
    ASSERT_EQ(with.height(), width / 2);
    CameraSpec spec;
    spec.width = width;
    spec.height = width / 2;
    const Camera camera(spec, glm::dvec3(0.0));
    double fx = 0, fy = 0;
    ASSERT_TRUE(camera.direction_to_film(table->sun.direction(), &fx, &fy));
    // The brightest pixel is (next to) the sun's.
    int bx = 0, by = 0;
    double best = -1, energy = 0;
    for (int y = 0; y < with.height(); ++y)
      for (int x = 0; x < width; ++x) {
        const double Y = with.luminance(x, y);
        if (Y > best) best = Y, bx = x, by = y;
        energy += (Y - without.luminance(x, y)) * camera.pixel_solid_angle(x, y);
      }
    EXPECT_LE(std::abs(bx - static_cast<int>(fx)), 1) << width;
    EXPECT_LE(std::abs(by - static_cast<int>(fy)), 1) << width;
    // The disk's ~1e9 cd/m^2 spread over the pixel: ~200x the aureole at 64 px, more when finer.
    EXPECT_GT(best, (width >= 512 ? 1e3 : 1e2) * without.luminance(bx, by)) << width;
    // Sum of the disk's luminance x pixel solid angle = mean disk luminance x disk solid angle.
    const SunDiskSummary disk = sun_disk_summary(*table);
    EXPECT_NEAR(energy, disk.illuminance_lux, 1e-3 * disk.illuminance_lux) << width;
    EXPECT_GT(disk.xyz.y, 1e8) << "the disk at 60 degrees is ~1e9 cd/m^2";
  }
}

// Integrals of a map's luminance: over the sphere (the mean luminance times
// 4 pi) and cosine-weighted over the upper hemisphere (the horizontal
// illuminance, lux).  Lat-long pixels: the exact solid angle and cosine
// integral of each latitude band; equal-area pixels: 4 pi / N^2 each, the
// cosine taken at the pixel's 4 x 4 sub-centres.
struct MapIntegrals {
  double sphere = 0.0, horizontal = 0.0;
};

MapIntegrals latlong_integrals(const Image& image) {
  MapIntegrals m;
  const int w = image.width(), h = image.height();
  for (int y = 0; y < h; ++y) {
    const double t0 = M_PI * y / h, t1 = M_PI * (y + 1) / h;  // polar angle band
    const double omega = 2.0 * M_PI / w * (std::cos(t0) - std::cos(t1));
    // integral of cos(theta) sin(theta) dtheta over the band, upper hemisphere only
    const double a = std::min(t0, M_PI / 2), b = std::min(t1, M_PI / 2);
    const double cos_omega = 2.0 * M_PI / w * 0.5 * (std::sin(b) * std::sin(b) - std::sin(a) * std::sin(a));
    for (int x = 0; x < w; ++x) {
      m.sphere += image.luminance(x, y) * omega;
      m.horizontal += image.luminance(x, y) * cos_omega;
    }
  }
  return m;
}

MapIntegrals equal_area_integrals(const Image& image) {
  MapIntegrals m;
  const int n = image.width();
  const double omega = equal_area_pixel_solid_angle(n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double cosine = 0.0;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          cosine += std::max(0.0, equal_area_square_to_sphere({(x + (i + 0.5) / 4) / n, (y + (j + 0.5) / 4) / n}).z);
      m.sphere += image.luminance(x, y) * omega;
      m.horizontal += image.luminance(x, y) * omega * cosine / 16.0;
    }
  return m;
}

// With refraction the splatted disk of the sun at geometric zenith 90 deg
// shows lifted by ~28' (one 0.35-degree pixel row or two at width 1024) and
// carries its flattened solid angle: its energy is the straight disk's
// times ~0.86 (the flattening) and the transmittance along the apparent
// rays (the disk is lifted out of the densest air: more than the straight
// disk at the horizon, whose lower half the planet hides).
TEST(SkyServiceEnvmap, RefractedDiskIsLiftedAndKeepsFiniteEnergy) {
  SkyTableParams straight = params(90.0, 90.0), refracted = params(90.0, 90.0);
  refracted.atmosphere.refraction = true;
  const int width = 1024;
  CameraSpec spec;
  spec.width = width;
  spec.height = width / 2;
  const Camera camera(spec, glm::dvec3(0.0));
  double rows[2] = {0.0, 0.0}, energies[2] = {0.0, 0.0};
  int k = 0;
  for (const auto* p : {&straight, &refracted}) {
    const auto table = build_sky_table(*p);
    const Image with = render_envmap(*table, width, EnvmapSun::kDisk, 2);
    const Image without = render_envmap(*table, width, EnvmapSun::kNone, 2);
    double weight = 0.0, row = 0.0;
    for (int y = 0; y < with.height(); ++y)
      for (int x = 0; x < width; ++x) {
        const double e = (with.luminance(x, y) - without.luminance(x, y)) * camera.pixel_solid_angle(x, y);
        ASSERT_TRUE(std::isfinite(e));
        weight += std::max(0.0, e);
        row += std::max(0.0, e) * (y + 0.5);
      }
    rows[k] = row / weight;
    energies[k] = weight;
    ++k;
  }
  const double pixel_deg = 180.0 / (width / 2);
  EXPECT_NEAR((rows[0] - rows[1]) * pixel_deg * 60.0, 28.0, 12.0) << "lifted by the horizon refraction";
  EXPECT_GT(energies[1], 0.0);
}

TEST(SkyServiceEnvmap, EqualAreaMapHoldsTheLatLongMapsFlux) {
  // Two independent discretisations of one sky: their integrals agree to
  // 0.5 %, the disk's energy is exact in both (1e-3, as above), and the
  // sun's pixel is where equal_area_sphere_to_square puts its direction.
  for (auto [zenith, azimuth] : {std::pair{60.0, 100.0}, std::pair{30.0, 215.0}}) {
    const auto table = build_sky_table(params(zenith, azimuth));
    // Pixels of ~0.4 deg: the disk's cosine weight is its pixel's (0.1 % of
    // its illuminance at most), the sky's gradients are resolved.
    constexpr int n = 512;
    const Image latlong = render_envmap(*table, 2 * n, EnvmapSun::kDisk, 2);
    const Image square = render_envmap_equal_area(*table, n, EnvmapSun::kDisk, 2);
    const Image bare = render_envmap_equal_area(*table, n, EnvmapSun::kNone, 2);
    ASSERT_EQ(square.width(), n);
    ASSERT_EQ(square.height(), n);
    const MapIntegrals a = latlong_integrals(latlong), b = equal_area_integrals(square);
    EXPECT_NEAR(b.sphere, a.sphere, 5e-3 * a.sphere) << zenith;
    EXPECT_NEAR(b.horizontal, a.horizontal, 5e-3 * a.horizontal) << zenith;
    // The disk alone: its normal illuminance times cos(zenith) on the horizontal.
    const SunDiskSummary disk = sun_disk_summary(*table);
    const MapIntegrals sky = equal_area_integrals(bare);
    EXPECT_NEAR(b.sphere - sky.sphere, disk.illuminance_lux, 1e-3 * disk.illuminance_lux) << zenith;
    // The brightest pixel is the sun's.
    const glm::dvec2 p = equal_area_sphere_to_square(table->sun.direction());
    int bx = 0, by = 0;
    double best = -1;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        if (square.luminance(x, y) > best) best = square.luminance(x, y), bx = x, by = y;
    EXPECT_LE(std::abs(bx - static_cast<int>(p.x * n)), 1) << zenith;
    EXPECT_LE(std::abs(by - static_cast<int>(p.y * n)), 1) << zenith;
    // ... and it lies in the sun's quadrant of the observer frame: the image
    // is read as x east, y north (down), z zenith (the centre).
    const double east = std::sin(azimuth * M_PI / 180.0), north = std::cos(azimuth * M_PI / 180.0);
    EXPECT_EQ(bx > n / 2, east > 0) << zenith;
    EXPECT_EQ(by > n / 2, north > 0) << zenith;
  }
}

TEST(SkyServiceEnvmap, EncodesAFloatLatLongExr) {
  const auto table = build_sky_table(params(50.0, 0.0));
  Image image = render_envmap(*table, 32, EnvmapSun::kDisk, 1);
  image.set_metadata("method", std::string("lut"));
  const std::string bytes = encode_envmap_exr(image);
  ASSERT_GT(bytes.size(), 100u);
  EXPECT_EQ(bytes.substr(0, 4), std::string("\x76\x2f\x31\x01", 4));  // OpenEXR magic
  EXPECT_NE(bytes.find("envmap"), std::string::npos);
  EXPECT_EQ(bytes, encode_envmap_exr(image)) << "deterministic bytes";
}

}  // namespace
}  // namespace skyfarm::server

// The procedural cloud layer: its majorants bound the density along every
// kind of ray (the unbiasedness of delta and ratio tracking rests on it), the
// coverage's extremes, the optical-depth mode against direct integration,
// the wind's translation and determinism.
#include "common/clouds/cloud_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>

#include "common/clouds/cloud_profile.h"
#include "common/clouds/scene_clouds.h"
#include "common/clouds/shell_intervals.h"
#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"
#include "common/render/render_setup.h"
#include "tests/support/cloud_slab_scene.h"
#include "common/sampling/sampler.h"

namespace skyfarm {
namespace {

constexpr double kR = kEarthRadius_m;
const glm::dvec3 kObserver{0.0, 0.0, kR};

CloudLayerSpec layer_spec(CloudType type, double coverage) {
  CloudLayerSpec s = cloud_layer_preset(type);
  s.coverage = coverage;
  return s;
}

// A point in the layer near the observer: horizontal offsets within
// `extent_m`, the altitude a share x of the layer's thickness.
glm::dvec3 point_in_layer(const CloudLayerSpec& s, double east_m, double north_m, double x) {
  const glm::dvec3 dir = glm::normalize(glm::dvec3(east_m, north_m, kR));
  return dir * (kR + s.base_m + x * s.thickness_m);
}

struct Piece {
  double t0, t1, sigma;
};

std::vector<Piece> pieces_of(const CloudField& field, const Ray& ray, double t_begin, double t_end) {
  std::vector<Piece> out;
  field.for_each_majorant(ray, t_begin, t_end, [&](double t0, double t1, double s) {
    out.push_back({t0, t1, s});
    return true;
  });
  return out;
}

// Random rays of every kind the renderer sends through a layer: from the
// ground, from inside the layer, from 400 km and 36 000 km (looking at the
// layer near the sub-orbit point), and grazing (tangent to a sphere inside
// or just under the layer, so the ray runs hundreds of km in it).
Ray random_ray(const CloudLayerSpec& s, int kind, std::uint64_t i) {
  const auto u = [&](std::uint64_t dim) { return to_unit(hash_keys(77, static_cast<std::uint64_t>(kind), i, dim)); };
  const double az = 2.0 * kPi * u(0);
  const glm::dvec3 horizontal{std::sin(az), std::cos(az), 0.0};
  switch (kind) {
    case 0: {  // ground, upper hemisphere
      const glm::dvec3 o{20000.0 * (u(1) - 0.5), 20000.0 * (u(2) - 0.5), kR};
      const double mu = u(3);
      return {o, glm::normalize(horizontal * std::sqrt(1.0 - mu * mu) + glm::dvec3(0, 0, mu))};
    }
    case 1: {  // inside the layer, any direction
      const glm::dvec3 o = point_in_layer(s, 20000.0 * (u(1) - 0.5), 20000.0 * (u(2) - 0.5), u(3));
      const double mu = 2.0 * u(4) - 1.0;
      return {o, glm::normalize(horizontal * std::sqrt(1.0 - mu * mu) + glm::dvec3(0, 0, mu))};
    }
    case 2:
    case 3: {  // orbit: 400 km or geostationary, towards a point of the layer
      const double altitude = kind == 2 ? 400e3 : 35786e3;
      const glm::dvec3 o = glm::normalize(glm::dvec3(0.3 * (u(1) - 0.5), 0.3 * (u(2) - 0.5), 1.0)) * (kR + altitude);
      const glm::dvec3 target = point_in_layer(s, 40000.0 * (u(3) - 0.5), 40000.0 * (u(4) - 0.5), u(5));
      return {o, glm::normalize(target - o)};
    }
    default: {  // grazing: tangent at a radius from 50 m under the layer to its top
      const double r_tangent = kR + s.base_m - 50.0 + (s.thickness_m + 50.0) * u(1);
      const glm::dvec3 tangent_point = glm::dvec3(0, 0, r_tangent);
      const glm::dvec3 o = tangent_point - 200e3 * horizontal;
      return {o, horizontal};
    }
  }
}

// For every visited piece: dense samples (ends, stratified points) have
// sigma_t <= sigma_maj; the pieces keep the contract's order; inside the
// shell but outside every piece (1 mm away from piece ends) sigma_t == 0.
void check_bounds(const CloudLayer& layer, const CloudLayerSpec& s, int rays_per_kind, int samples_per_piece) {
  std::uint64_t pieces_total = 0, zero_checks = 0;
  double covered = 0.0, shell_length = 0.0;
  for (int kind = 0; kind < 5; ++kind) {
    for (int i = 0; i < rays_per_kind; ++i) {
      const Ray ray = random_ray(s, kind, static_cast<std::uint64_t>(i));
      const double t_end = 1e9;
      const std::vector<Piece> pieces = pieces_of(layer, ray, 0.0, t_end);
      double last = 0.0;
      for (const Piece& p : pieces) {
        ASSERT_GE(p.t0, last) << "kind " << kind << " ray " << i;
        ASSERT_LT(p.t0, p.t1);
        ASSERT_LE(p.t1, t_end);
        ASSERT_TRUE(std::isfinite(p.sigma) && p.sigma > 0.0);
        last = p.t1;
        covered += p.t1 - p.t0;
        for (int k = 0; k <= samples_per_piece + 1; ++k) {
          const double t = k == 0 ? p.t0 : k > samples_per_piece ? p.t1
                                    : p.t0 + (p.t1 - p.t0) * (k - 1 + to_unit(hash_keys(5, i, k, kind))) / samples_per_piece;
          const double sigma = layer.sigma_t(ray.at(t));
          ASSERT_LE(sigma, p.sigma) << "kind " << kind << " ray " << i << " t " << t;
        }
      }
      pieces_total += pieces.size();
      // The gaps inside the shell.
      const ShellIntervals shell =
          shell_intervals(ray, kR + layer.bottom_altitude_m(), kR + layer.top_altitude_m(), 0.0, t_end);
      for (int k = 0; k < shell.count; ++k) {
        const double a = shell.t0[static_cast<std::size_t>(k)], b = shell.t1[static_cast<std::size_t>(k)];
        shell_length += b - a;
        const int n = 400;
        for (int j = 0; j < n; ++j) {
          const double t = a + (b - a) * (j + 0.5) / n;
          bool in_piece = false;
          for (const Piece& p : pieces) in_piece |= t > p.t0 - 1e-3 && t < p.t1 + 1e-3;
          if (in_piece) continue;
          ++zero_checks;
          ASSERT_EQ(layer.sigma_t(ray.at(t)), 0.0) << "kind " << kind << " ray " << i << " t " << t;
        }
      }
    }
  }
  EXPECT_GT(pieces_total, 0u);
  // Partial cover: cloud-free cells are skipped, so some of the shell is left out.
  if (s.coverage < 0.6) {
    EXPECT_GT(zero_checks, 0u);
    EXPECT_LT(covered, 0.9 * shell_length) << covered / shell_length;
  }
}

TEST(CloudLayer, MajorantsBoundTheDensityAlongEveryKindOfRay) {
  const CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.4);
  check_bounds(CloudLayer(s, kR, glm::dvec3(0.0)), s, 12, 24);
}

TEST(CloudLayer, MajorantsBoundEveryTypeAndAHugeDrift) {
  // Seconds since J2000 (~8e8 in 2025) x 12 m/s: the lattice indices are
  // ~3e6 and the points' coordinates ~1e10 m.
  const glm::dvec3 drift{8.1e8 * 12.0, -8.1e8 * 5.0, 0.0};
  for (const CloudType type :
       {CloudType::kStratocumulus, CloudType::kStratus, CloudType::kCirrus, CloudType::kCustom}) {
    CloudLayerSpec s = layer_spec(type, 0.5);
    s.erosion = 0.7;
    s.seed = 11;
    SCOPED_TRACE(std::string(cloud_type_name(type)));
    check_bounds(CloudLayer(s, kR, drift), s, 4, 12);
  }
}

TEST(CloudLayer, CoverageZeroIsClearAndOneIsOvercast) {
  CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.0);
  const CloudLayer clear(s, kR, glm::dvec3(0.0));
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 p = point_in_layer(s, 1e5 * (to_unit(hash_keys(1, i, 0, 0)) - 0.5),
                                        1e5 * (to_unit(hash_keys(1, i, 1, 0)) - 0.5), to_unit(hash_keys(1, i, 2, 0)));
    ASSERT_EQ(clear.sigma_t(p), 0.0);
  }
  for (int kind = 0; kind < 5; ++kind)
    EXPECT_TRUE(pieces_of(clear, random_ray(s, kind, 0), 0.0, 1e9).empty()) << kind;

  // Overcast: with no erosion the density is the profile itself everywhere.
  s.coverage = 1.0;
  s.erosion = 0.0;
  const CloudLayer overcast(s, kR, glm::dvec3(0.0));
  const CloudProfile profile = CloudProfile::for_type(s.type);
  for (int i = 0; i < 2000; ++i) {
    const double x = to_unit(hash_keys(2, i, 2, 0));
    const glm::dvec3 p = point_in_layer(s, 1e5 * (to_unit(hash_keys(2, i, 0, 0)) - 0.5),
                                        1e5 * (to_unit(hash_keys(2, i, 1, 0)) - 0.5), x);
    ASSERT_NEAR(overcast.density(p), profile(x), 1e-9) << x;
  }
  // With erosion the cores stay: most of the plateau is still cloud.
  s.erosion = 0.4;
  const CloudLayer eroded(s, kR, glm::dvec3(0.0));
  int cloudy = 0;
  for (int i = 0; i < 1000; ++i)
    cloudy += eroded.density(point_in_layer(s, 1e5 * (to_unit(hash_keys(3, i, 0, 0)) - 0.5),
                                            1e5 * (to_unit(hash_keys(3, i, 1, 0)) - 0.5), 0.2)) > 0.0;
  EXPECT_GT(cloudy, 900);
}

TEST(CloudLayer, MeanDensityGrowsWithCoverageAndTheCoveredShareIsIt) {
  double last_mean = -1.0, last_area = -1.0;
  for (const double coverage : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    const CloudLayerSpec s = layer_spec(CloudType::kCumulus, coverage);
    const CloudLayer layer(s, kR, glm::dvec3(0.0));
    CloudLayerSpec uneroded_spec = s;
    uneroded_spec.erosion = 0.0;
    const CloudLayer uneroded(uneroded_spec, kR, glm::dvec3(0.0));
    double sum = 0.0;
    int area = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const double e = 2e5 * (to_unit(hash_keys(4, i, 0, 0)) - 0.5), nn = 2e5 * (to_unit(hash_keys(4, i, 1, 0)) - 0.5);
      sum += layer.density(point_in_layer(s, e, nn, to_unit(hash_keys(4, i, 2, 0))));
      area += uneroded.density(point_in_layer(s, e, nn, 0.2)) > 0.0;  // on the plateau
    }
    const double mean = sum / n, covered = static_cast<double>(area) / n;
    EXPECT_GT(mean, last_mean) << coverage;
    EXPECT_GT(covered, last_area) << coverage;
    // The coverage is the share of the area holding cloud (on the plateau,
    // before erosion eats the edges); ~70 features
    // across the sampled 200 km give a sampling error of a few per cent.
    EXPECT_NEAR(covered, coverage, 0.06) << coverage;
    last_mean = mean;
    last_area = covered;
  }
}

// optical_depth > 0 fixes sigma_max so that a vertical ray through a
// full (coverage 1, no erosion) layer has that optical depth: checked by
// the midpoint rule over the whole vertical line (not using the majorants)
// and by SceneClouds::optical_depth (using them).
TEST(CloudLayer, OpticalDepthModeGivesTheRequestedVerticalDepth) {
  for (const CloudType type : {CloudType::kCumulus, CloudType::kStratus, CloudType::kCirrus}) {
    CloudLayerSpec s = layer_spec(type, 1.0);
    s.erosion = 0.0;
    s.optical_depth = 12.0;
    auto layer = std::make_shared<CloudLayer>(s, kR, glm::dvec3(0.0));
    const Ray up{glm::dvec3(3000.0, -2000.0, kR), glm::normalize(glm::dvec3(3000.0, -2000.0, kR))};
    // Midpoint rule, 1 m steps over the layer (the profile's smoothsteps are
    // C1 with |p''| <= 6 / (rise width)^2: error << 1e-6).
    double tau = 0.0;
    const int n = static_cast<int>(s.thickness_m);
    for (int i = 0; i < n; ++i) tau += layer->sigma_t(up.at(s.base_m + (i + 0.5) * s.thickness_m / n));
    tau *= s.thickness_m / n;
    EXPECT_NEAR(tau, 12.0, 12.0 * 1e-5) << cloud_type_name(type);
    const SceneClouds clouds({layer});
    EXPECT_NEAR(clouds.optical_depth(up, 0.0, 1e6, 1.0), 12.0, 12.0 * 1e-5) << cloud_type_name(type);
  }
  // The water-content mode: sigma_max = LWC x the optics' extinction (~0.15 m^-1 per g m^-3 at 10 um).
  const CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.5);
  const CloudLayer layer(s, kR, glm::dvec3(0.0));
  EXPECT_DOUBLE_EQ(layer.sigma_max(), s.water_content_g_m3 * layer.optics().extinction_per_g_m3);
  EXPECT_GT(layer.sigma_max(), 0.01);
}

// The wind translates the noise: a layer drifted by d has at p the density
// a still layer has at p - d, wherever the height profile is the same at
// both (here: its plateau, so the bits must agree exactly).
TEST(CloudLayer, TheDriftTranslatesTheField) {
  CloudLayerSpec s = layer_spec(CloudType::kCustom, 0.5);
  s.thickness_m = 2000.0;
  const CloudProfile profile = CloudProfile::for_type(s.type);
  for (const glm::dvec3 drift : {glm::dvec3(600.0, 0.0, 0.0), glm::dvec3(-25000.0, 17000.0, 0.0)}) {
    const CloudLayer moved(s, kR, drift), still(s, kR, glm::dvec3(0.0));
    int compared = 0, cloudy = 0;
    for (int i = 0; i < 3000; ++i) {
      const glm::dvec3 p = point_in_layer(s, 6e4 * (to_unit(hash_keys(6, i, 0, 0)) - 0.5),
                                          6e4 * (to_unit(hash_keys(6, i, 1, 0)) - 0.5),
                                          0.3 + 0.4 * to_unit(hash_keys(6, i, 2, 0)));
      const glm::dvec3 q = p - drift;
      const double xq = (glm::length(q) - kR - s.base_m) / s.thickness_m;
      if (profile(xq) != 1.0) continue;
      ++compared;
      cloudy += moved.density(p) > 0.0;
      ASSERT_EQ(moved.density(p), still.density(q));
    }
    EXPECT_GT(compared, 1000);
    EXPECT_GT(cloudy, 100);
  }
}

// A timelapse's frames one minute apart with a 10 m/s wind (600 m): the
// fields differ, yet stay correlated (the features are 3 km across).
TEST(CloudLayer, FramesAMinuteApartAreDifferentButCorrelated) {
  const CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.5);
  const double t0 = 8.1e8;  // seconds since J2000, in 2025
  const CloudLayer a(s, kR, glm::dvec3(10.0 * t0, 0.0, 0.0)), b(s, kR, glm::dvec3(10.0 * (t0 + 60.0), 0.0, 0.0));
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int differ = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 p = point_in_layer(s, 1e5 * (to_unit(hash_keys(8, i, 0, 0)) - 0.5),
                                        1e5 * (to_unit(hash_keys(8, i, 1, 0)) - 0.5), 0.3);
    const double da = a.density(p), db = b.density(p);
    differ += da != db;
    sa += da, sb += db, saa += da * da, sbb += db * db, sab += da * db;
  }
  const double cov = sab / n - sa / n * sb / n;
  const double corr = cov / std::sqrt((saa / n - sa / n * sa / n) * (sbb / n - sb / n * sb / n));
  EXPECT_GT(differ, n / 10);
  EXPECT_GT(corr, 0.5);
  EXPECT_LT(corr, 0.999);
}

// The majorants in use: delta tracking's chance of passing a ray with no
// collision, and ratio tracking's mean transmittance, both equal
// exp(-tau) with tau integrated directly along the ray (1 m midpoint steps
// over the shell, not using the majorants), within 4 standard errors.
TEST(CloudLayer, TrackingThroughTheLayerIsUnbiased) {
  CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.5);
  s.optical_depth = 1.5;  // sigma_max ~ 1.7e-3 m^-1: rays through cores and gaps alike
  auto layer = std::make_shared<CloudLayer>(s, kR, glm::dvec3(1e9, -3e8, 0.0));
  const SceneClouds clouds({layer});
  int checked = 0;
  for (std::uint64_t r = 0; r < 24 && checked < 6; ++r) {
    const Ray ray = random_ray(s, r % 2 == 0 ? 0 : 2, r);
    const double t_end = 1e8;
    const ShellIntervals shell = shell_intervals(ray, kR + s.base_m, kR + s.base_m + s.thickness_m, 0.0, t_end);
    double tau = 0.0;
    for (int k = 0; k < shell.count; ++k) {
      const double a = shell.t0[static_cast<std::size_t>(k)], b = shell.t1[static_cast<std::size_t>(k)];
      const int n = static_cast<int>(std::ceil(b - a));
      for (int j = 0; j < n; ++j) tau += layer->sigma_t(ray.at(a + (j + 0.5) * (b - a) / n)) * (b - a) / n;
    }
    if (tau < 0.2 || tau > 3.0) continue;  // a ray with something to test, not hopeless
    ++checked;
    const double expected = std::exp(-tau);
    const int n = 6000;
    double sum = 0.0, sum2 = 0.0;
    int passed = 0;
    std::uint64_t collisions = 0;
    for (int i = 0; i < n; ++i) {
      Sampler a(21, r, static_cast<std::uint64_t>(i)), b(22, r, static_cast<std::uint64_t>(i));
      passed += !clouds.sample_collision(ray, 0.0, t_end, a, &collisions).has_value();
      const double T = clouds.transmittance(ray, 0.0, t_end, b, &collisions);
      sum += T, sum2 += T * T;
    }
    const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    const double p = static_cast<double>(passed) / n, p_se = std::sqrt(expected * (1.0 - expected) / n);
    EXPECT_NEAR(mean, expected, 4.0 * se + 1e-6) << "ray " << r << " tau " << tau;
    EXPECT_NEAR(p, expected, 4.0 * p_se) << "ray " << r << " tau " << tau;
  }
  EXPECT_EQ(checked, 6);
}

// Radiative transfer in a plane-parallel medium depends on the altitude only
// through the optical depth (Chandrasekhar 1960, ch. I; Liou 2002, sec.
// 6.1): an overcast layer (coverage 1, no erosion), whose extinction follows
// its height profile, reflects as a uniform slab of the same vertical
// optical depth and optics.  The path-traced reflectances of both agree
// within 4 combined standard errors.  (The transmitted flux, and the
// reflected one of thicker clouds, hold the Mie forward peak's spikes: their
// standard errors at these sample counts are ~0.2, too large to test anything.)
TEST(CloudLayer, AnOvercastLayerReflectsAsAUniformSlab) {
  const double tau = 4.0, zenith = 40.0;
  CloudLayerSpec s = layer_spec(CloudType::kStratus, 1.0);
  s.erosion = 0.0;
  s.optical_depth = tau;
  s.base_m = testing::kSlabBottom_m;
  s.thickness_m = testing::kSlabTop_m - testing::kSlabBottom_m;
  const auto scene = [&](bool layered, double observer_altitude_m) {
    auto sc = testing::cloud_slab_scene(tau, CloudOptics{}, zenith, observer_altitude_m);
    const double radius = sc->atmosphere().planet_radius_m();
    auto layer = std::make_shared<CloudLayer>(s, radius, glm::dvec3(0.0));
    std::shared_ptr<const CloudField> field = layer;
    if (!layered)
      field = std::make_shared<UniformCloudSlab>(radius, s.base_m, s.base_m + s.thickness_m,
                                                 tau / s.thickness_m, layer->optics());
    sc->set_clouds(std::make_shared<SceneClouds>(std::vector<std::shared_ptr<const CloudField>>{field}));
    return sc;
  };
  const int n = 12000;
  const double altitude = s.base_m + s.thickness_m + 1.0;  // above, looking down
  const testing::FluxEstimate layer = testing::hemisphere_flux_ratio(*scene(true, altitude), false, n, 31);
  const testing::FluxEstimate slab = testing::hemisphere_flux_ratio(*scene(false, altitude), false, n, 32);
  EXPECT_EQ(layer.counters.nonfinite, 0u);
  const double se = std::hypot(layer.se, slab.se);
  EXPECT_LT(se, 0.03);  // R ~ 0.19; tau 8 would give ~1.5 times more (two-stream, g 0.86)
  EXPECT_GT(slab.mean, 0.1);
  EXPECT_NEAR(layer.mean, slab.mean, 4.0 * se) << layer.mean << " vs " << slab.mean << ", se " << se;
}

// The render setup drifts each layer by time since J2000 x its wind along
// the observer's east (+x) and north (+y); a spec without a time does not.
TEST(CloudLayer, TheRenderSetupDriftsLayersByTheWindSinceJ2000) {
  RenderSpec spec;
  CloudLayerSpec s = layer_spec(CloudType::kCumulus, 0.5);
  s.wind_m_s = {12.0, -4.0};
  spec.clouds.layers = {s};
  spec.time = UtcInstant{946728000 + 3600, 0.5};  // J2000 + 3600.5 s
  const auto clouds = make_scene_clouds(spec, kR, nullptr);
  ASSERT_TRUE(clouds);
  ASSERT_EQ(clouds->fields().size(), 1u);
  const CloudLayer expected(s, kR, glm::dvec3(12.0 * 3600.5, -4.0 * 3600.5, 0.0)), still(s, kR, glm::dvec3(0.0));
  spec.time.reset();
  const auto timeless = make_scene_clouds(spec, kR, nullptr);
  int differ = 0;
  for (int i = 0; i < 500; ++i) {
    const glm::dvec3 p = point_in_layer(s, 3e4 * (to_unit(hash_keys(10, i, 0, 0)) - 0.5),
                                        3e4 * (to_unit(hash_keys(10, i, 1, 0)) - 0.5), to_unit(hash_keys(10, i, 2, 0)));
    ASSERT_EQ(clouds->fields()[0]->sigma_t(p), expected.sigma_t(p));
    ASSERT_EQ(timeless->fields()[0]->sigma_t(p), still.sigma_t(p));
    differ += expected.sigma_t(p) != still.sigma_t(p);
  }
  EXPECT_GT(differ, 100);
}

TEST(CloudLayer, SameSpecSameBitsOtherSeedOtherField) {
  CloudLayerSpec s = layer_spec(CloudType::kStratocumulus, 0.6);
  const CloudLayer a(s, kR, glm::dvec3(1e9, 2e9, 0.0)), b(s, kR, glm::dvec3(1e9, 2e9, 0.0));
  s.seed = 2;
  const CloudLayer c(s, kR, glm::dvec3(1e9, 2e9, 0.0));
  int differ = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 p = point_in_layer(s, 1e5 * (to_unit(hash_keys(9, i, 0, 0)) - 0.5),
                                        1e5 * (to_unit(hash_keys(9, i, 1, 0)) - 0.5), to_unit(hash_keys(9, i, 2, 0)));
    ASSERT_EQ(a.sigma_t(p), b.sigma_t(p));
    differ += a.sigma_t(p) != c.sigma_t(p);
  }
  EXPECT_GT(differ, 500);
  const Ray ray = random_ray(s, 4, 3);
  const auto pa = pieces_of(a, ray, 0.0, 1e9), pb = pieces_of(b, ray, 0.0, 1e9);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa[i].t0, pb[i].t0);
    EXPECT_EQ(pa[i].t1, pb[i].t1);
    EXPECT_EQ(pa[i].sigma, pb[i].sigma);
  }
}

TEST(CloudLayer, VisitingStopsWhenTheVisitorSaysSo) {
  const CloudLayerSpec s = layer_spec(CloudType::kStratus, 1.0);
  const CloudLayer layer(s, kR, glm::dvec3(0.0));
  int calls = 0;
  layer.for_each_majorant(random_ray(s, 4, 0), 0.0, 1e9, [&](double, double, double) { return ++calls < 3; });
  EXPECT_EQ(calls, 3);
}

TEST(CloudLayer, RejectsASpecOutOfRange) {
  const auto make = [](auto edit) {
    CloudLayerSpec s;
    edit(s);
    return CloudLayer(s, kR, glm::dvec3(0.0));
  };
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.coverage = 1.5; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.erosion = -0.1; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.thickness_m = 0.0; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.scale_m = -1.0; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.detail_scale_m = 0.0; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.base_m = -10.0; }), std::invalid_argument);
  EXPECT_THROW(make([](CloudLayerSpec& s) { s.optical_depth = -1.0; }), std::invalid_argument);
  EXPECT_NO_THROW(make([](CloudLayerSpec&) {}));
}

}  // namespace
}  // namespace skyfarm

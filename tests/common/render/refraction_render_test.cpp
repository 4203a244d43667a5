// Rendering with "atmosphere.refraction": the sun at geometric zenith 90.5 deg
// (hidden without refraction) seen lifted, flattened and with coloured rims;
// the high sun unchanged; the extreme views from orbit finite and bounded.
//
// References: the apparent elevation of the sun's centre from the ray-traced
// table (RefractionTable, checked against Auer & Standish's integral to
// < 0.1", docs/physics.md) and from Bennett's (1982) formula
// R = cot(h + 7.31 / (h + 4.4)) arcmin (h the apparent elevation in degrees;
// it fits observed refraction, 34.5' at the horizon, ~1.5' more than US76's
// 33.0' at 15 degC near the ground: docs/experiments/2026-12-07-refraction.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/core/constants.h"
#include "common/render/local_render.h"
#include "common/render/radiance_probe.h"
#include "tests/support/sun_specs.h"

namespace skyfarm {
namespace {

constexpr double kR = 6371000.0;
constexpr double kSunZenith = 90.5;
constexpr double kSunAzimuth = 90.0;  // east
constexpr double kSunRadius = 0.2666;

const AtmosphereRefraction& model() { return *AtmosphereRefraction::shared(kR, 100000.0); }

glm::dvec3 view(double elevation_deg, double azimuth_deg) {
  return direction_from_zenith_azimuth((90.0 - elevation_deg) * kDegToRad, azimuth_deg * kDegToRad);
}

Scene sunset_scene(bool refraction, double sun_zenith = kSunZenith, double altitude_m = 0.0) {
  AtmosphereSpec atmosphere;
  atmosphere.refraction = refraction;
  return Scene::from_specs(atmosphere, testing::sun_spec(sun_zenith, kSunAzimuth, kSunRadius),
                           Location{0.0, 0.0, altitude_m}, std::nullopt, 360.0, 830.0);
}

// Whether the camera ray at (elevation, azimuth) from the ground, bent at
// lambda as the path tracer bends it (bent_path.h), leaves into the sun disk.
bool sees_sun(const Sun& sun, double elevation_deg, double azimuth_deg, double lambda_nm) {
  BentPath path;
  model().trace({0.0, 0.0, kR}, view(elevation_deg, azimuth_deg), lambda_nm, &path);
  return path.outcome == RefractedRay::Outcome::kEscaped && sun.contains(path.exit_direction);
}

// The edge between inside (at a) and outside (at b) of a monotone test, by bisection.
template <class Inside>
double edge(double a, double b, Inside inside) {
  for (int i = 0; i < 50; ++i) {
    const double m = 0.5 * (a + b);
    (inside(m) ? a : b) = m;
  }
  return 0.5 * (a + b);
}

struct Disk {
  double bottom_deg, top_deg, centre_deg, width_deg;  // apparent; width as an angle on the sky
};

Disk apparent_disk(double lambda_nm, double sun_zenith) {
  const Sun sun = testing::sun_from_angles(sun_zenith, kSunAzimuth, kSunRadius);
  const double centre = *model().apparent_elevation_deg(0.0, 90.0 - sun_zenith + 0.1, lambda_nm);
  EXPECT_TRUE(sees_sun(sun, centre, kSunAzimuth, lambda_nm));
  Disk d;
  d.top_deg = edge(centre, centre + 1.0, [&](double e) { return sees_sun(sun, e, kSunAzimuth, lambda_nm); });
  d.bottom_deg = edge(centre, centre - 1.0, [&](double e) { return sees_sun(sun, e, kSunAzimuth, lambda_nm); });
  d.centre_deg = 0.5 * (d.top_deg + d.bottom_deg);
  const double right =
      edge(kSunAzimuth, kSunAzimuth + 1.0, [&](double a) { return sees_sun(sun, d.centre_deg, a, lambda_nm); });
  const double left =
      edge(kSunAzimuth, kSunAzimuth - 1.0, [&](double a) { return sees_sun(sun, d.centre_deg, a, lambda_nm); });
  d.width_deg = (right - left) * std::cos(d.centre_deg * kDegToRad);
  return d;
}

// Bennett's refraction for apparent elevation h (degrees), in degrees.
double bennett_deg(double h) { return 1.0 / std::tan((h + 7.31 / (h + 4.4)) * kDegToRad) / 60.0; }

// The sun at geometric zenith 90.5 deg stands half above the sea-level
// horizon: its upper rim (true elevation -0.233 deg) at the table's apparent
// elevation, within 3' of Bennett's; the lower half below the horizon (the
// rays meet the ground: the disk ends at the apparent horizon, ~0).
TEST(RefractionRender, ApparentElevationMatchesTheTableAndBennett) {
  const Disk disk = apparent_disk(550.0, kSunZenith);
  const double rim_true = 90.0 - kSunZenith + kSunRadius;
  const double table = *model().apparent_elevation_deg(0.0, rim_true, 550.0);
  const double bennett = edge(2.0, -0.9, [&](double h) { return h - bennett_deg(h) > rim_true; });
  EXPECT_NEAR(disk.top_deg * 60.0, table * 60.0, 0.3);
  EXPECT_NEAR(disk.top_deg * 60.0, bennett * 60.0, 3.0);
  EXPECT_NEAR(disk.bottom_deg * 60.0, 0.0, 0.5) << "the horizon";
  // The sun at geometric zenith 90 deg, whole: its centre's image (the
  // disk's middle is not quite that: the flattening grows downwards).
  const Disk whole = apparent_disk(550.0, 90.0);
  const double centre_table = *model().apparent_elevation_deg(0.0, 0.0, 550.0);
  const double centre_bennett = edge(2.0, -0.9, [](double h) { return h - bennett_deg(h) > 0.0; });
  EXPECT_NEAR(whole.centre_deg * 60.0, centre_table * 60.0, 0.5);
  EXPECT_NEAR(whole.centre_deg * 60.0, centre_bennett * 60.0, 3.0);
}

// Flattening of the whole sun at geometric zenith 90 deg: vertical over
// horizontal extent as the table's map predicts,
// (e_a(e_t + alpha) - e_a(e_t - alpha)) / (2 alpha); ~0.85 here.
TEST(RefractionRender, DiskIsFlattenedAsTheTablePredicts) {
  const Disk disk = apparent_disk(550.0, 90.0);
  const double predicted = (*model().apparent_elevation_deg(0.0, kSunRadius, 550.0) -
                            *model().apparent_elevation_deg(0.0, -kSunRadius, 550.0)) /
                           (2.0 * kSunRadius);
  const double ratio = (disk.top_deg - disk.bottom_deg) / disk.width_deg;
  EXPECT_NEAR(ratio, predicted, 0.01);
  EXPECT_NEAR(disk.width_deg, 2.0 * kSunRadius, 0.002);
  EXPECT_LT(ratio, 0.95);
  EXPECT_GT(ratio, 0.7);
}

// Through the path tracer (probes at exact wavelengths): a direction just
// inside the top rim at 480 nm but outside at 650 nm sees the sun in green-
// blue only; one just inside the bottom rim at 650 nm but below it at 480 nm
// sees it in red only.  So the upper rim is bluer, the lower redder.
TEST(RefractionRender, UpperRimIsBluerThanTheLowerRim) {
  const Disk blue = apparent_disk(480.0, 90.0), red = apparent_disk(650.0, 90.0);
  EXPECT_GT(blue.top_deg, red.top_deg);
  EXPECT_GT(blue.bottom_deg, red.bottom_deg);
  const double top = 0.5 * (blue.top_deg + red.top_deg), bottom = 0.5 * (blue.bottom_deg + red.bottom_deg);
  const Scene scene = sunset_scene(true, 90.0);
  const ProbeResult r = probe_radiance(scene, {view(top, kSunAzimuth), view(bottom, kSunAzimuth)}, {480.0, 650.0},
                                       64, 5, 2);
  EXPECT_EQ(r.counters.nonfinite, 0u);
  const double top_ratio = r.radiance[0][0] / r.radiance[0][1];
  const double bottom_ratio = r.radiance[1][0] / r.radiance[1][1];
  EXPECT_GT(top_ratio, 10.0 * bottom_ratio) << top_ratio << " " << bottom_ratio;
}

// The path tracer sees the sun at its apparent place with refraction (the
// disk's radiance, ~1e2 at 650 nm through ~40 air masses, over a sky of ~3)
// and only sky there without it (the sun is below the horizon).  A camera
// ray reaches the disk only if its delta tracking crosses the whole grazing
// air (T ~ 0.7 %), hence the many samples.
TEST(RefractionRender, SunBelowTheHorizonIsSeenOnlyWithRefraction) {
  const double centre = *model().apparent_elevation_deg(0.0, 90.0 - kSunZenith, 650.0);
  const std::vector<glm::dvec3> dirs{view(centre, kSunAzimuth), view(centre + 1.0, kSunAzimuth)};
  const ProbeResult on = probe_radiance(sunset_scene(true), dirs, {650.0}, 3000, 3, 2);
  const ProbeResult off = probe_radiance(sunset_scene(false), dirs, {650.0}, 3000, 3, 2);
  EXPECT_EQ(on.counters.nonfinite + off.counters.nonfinite, 0u);
  EXPECT_GT(on.radiance[0][0], 10.0 * on.radiance[1][0]);
  EXPECT_LT(off.radiance[0][0], 2.0 * off.radiance[1][0]);
}

// A high sun: refraction moves the sky by at most ~1' there, so the two
// estimates agree within their noise (and the bent shadow rays' transmittance
// with the straight ones'): the radiance is conserved.
TEST(RefractionRender, HighSunSkyIsUnchangedWithinNoise) {
  const std::vector<glm::dvec3> dirs{view(30.0, 90.0), view(45.0, 270.0), view(5.0, 0.0)};
  const ProbeResult on = probe_radiance(sunset_scene(true, 30.0), dirs, {450.0, 600.0}, 1500, 7, 2);
  const ProbeResult off = probe_radiance(sunset_scene(false, 30.0), dirs, {450.0, 600.0}, 1500, 7, 2);
  EXPECT_EQ(on.counters.nonfinite, 0u);
  for (std::size_t d = 0; d < dirs.size(); ++d)
    for (std::size_t w = 0; w < 2; ++w) {
      const double a = on.radiance[d][w], b = off.radiance[d][w];
      const double se = std::hypot(on.standard_error[d][w], off.standard_error[d][w]);
      EXPECT_NEAR(a, b, 4.0 * se + 0.01 * b) << d << " " << w;
    }
}

// From 100 km and from geostationary orbit, looking through the limb at a
// sun 2 deg below the geometric horizon: rays enter from space, graze the
// ground or turn at a tangent point deep in the air (~2 x 33' of bending),
// and the sun shines through the limb.  Finite, non-negative, no path cut,
// and the chords per ray are bounded (the tracer's cap).
TEST(RefractionRender, LimbFromOrbitIsFiniteAndBounded) {
  for (const double altitude : {100000.0, 3.5786e7}) {
    const Scene scene = sunset_scene(true, 92.0, altitude);
    const double r = kR + altitude;
    std::vector<glm::dvec3> dirs;
    for (const double tangent_m : {0.0, 2000.0, 10000.0}) {
      const double zenith = 180.0 - std::asin((kR + tangent_m) / r) * kRadToDeg;
      dirs.push_back(direction_from_zenith_azimuth(zenith * kDegToRad, kSunAzimuth * kDegToRad));
    }
    const auto start = std::chrono::steady_clock::now();
    const ProbeResult p = probe_radiance(scene, dirs, {450.0, 650.0}, 100, 9, 2);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(p.counters.nonfinite, 0u);
    EXPECT_EQ(p.counters.depth_limit, 0u);
    for (const auto& row : p.radiance)
      for (const double L : row) EXPECT_TRUE(std::isfinite(L) && L >= 0.0) << L;
    EXPECT_LT(seconds, 15.0) << altitude;
    BentPath path;
    for (const glm::dvec3& d : dirs) {
      model().trace(scene.observer(), d, 450.0, &path);
      EXPECT_LE(path.chords.size(), 4u * static_cast<std::size_t>(model().shells(450.0).shell_count()) + 17u);
    }
  }
}

// A request end to end (api -> render setup -> tile renderer), path tracer
// and LUT: a narrow view aimed at the sunset (24 x 24 pixels of 4').  With
// refraction the disk's pixels are ~200 times the sky's median luminance
// (measured: the path tracer's disk 10^4.5-10^4.9 cd/m2 over a sky of
// 10^2.6), and those above a third of the peak lie between the horizon and
// the upper rim's apparent elevation, within the disk's azimuths; without,
// the peak is the sky's noise (~30 times its median at 4 spp).
struct SunPixels {
  int bright = 0;
  double peak_over_median = 0.0;
  double lowest_deg = 90.0, highest_deg = -90.0, widest_deg = 0.0;
};

SunPixels render_sunset(const char* method, bool refraction) {
  const std::string json = std::string(R"({"sun": {"zenith_deg": 90.5, "azimuth_deg": 90}, "camera": )") +
                           R"({"projection": "perspective", "width": 24, "height": 24, "yaw_deg": 90, )" +
                           R"("pitch_deg": 0.1, "fov_deg": 1.6}, "atmosphere": {"refraction": )" +
                           (refraction ? "true" : "false") + R"(}, "quality": {"samples_per_pixel": 16}, "method": ")" +
                           method + R"(", "output": {"half": false}, "seed": 3})";
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(json)));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  Image image(setup.plan.width, setup.plan.height);
  const LocalRenderResult result = render_image(renderer, &image, 2);
  EXPECT_EQ(result.counters.nonfinite, 0u);
  std::vector<double> values;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) values.push_back(image.luminance(x, y));
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  SunPixels s;
  s.peak_over_median = sorted.back() / median;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      if (values[static_cast<std::size_t>(y * 24 + x)] < sorted.back() / 3.0) continue;
      Ray ray;
      setup.camera->generate_ray(x, y, 0.5, 0.5, &ray);
      const double e = std::asin(ray.d.z) * kRadToDeg;
      ++s.bright;
      s.lowest_deg = std::min(s.lowest_deg, e);
      s.highest_deg = std::max(s.highest_deg, e);
      s.widest_deg = std::max(s.widest_deg, std::abs(std::atan2(ray.d.x, ray.d.y) * kRadToDeg - kSunAzimuth));
    }
  return s;
}

TEST(RefractionRender, RequestRendersTheLiftedSunPathAndLut) {
  const double rim = *model().apparent_elevation_deg(0.0, 90.0 - kSunZenith + kSunRadius, 550.0);
  const double pixel = 1.6 / 24.0;
  for (const char* method : {"path", "lut"}) {
    const SunPixels on = render_sunset(method, true), off = render_sunset(method, false);
    EXPECT_GT(on.peak_over_median, 100.0) << method;
    EXPECT_LT(on.highest_deg, rim + pixel) << method;
    EXPECT_GT(on.lowest_deg, -pixel) << method << ": nothing below the horizon";
    EXPECT_LT(on.widest_deg, kSunRadius + pixel) << method;
    EXPECT_LT(off.peak_over_median, 100.0) << method;
  }
}

// Scenes with objects and clouds keep working with refraction (the bent
// segments meet them chord by chord; the cloud sun lobe aims at the apparent
// sun): a glass and a gold ball at the feet and a cumulus layer, at sunset.
TEST(RefractionRender, ObjectsAndCloudsRenderFinite) {
  const std::string json = R"({"sun": {"zenith_deg": 89, "azimuth_deg": 270},
      "camera": {"projection": "perspective", "width": 24, "height": 16, "yaw_deg": 270, "pitch_deg": -10,
                 "fov_deg": 90},
      "atmosphere": {"refraction": true},
      "objects": [{"shape": "sphere", "material": {"name": "bk7", "roughness": 0}, "translate_m": [-4, -0.6, 0.4],
                   "scale": 0.4},
                  {"shape": "sphere", "material": {"name": "gold", "roughness": 0.05}, "translate_m": [-4, 0.8, 0.4],
                   "scale": 0.4}],
      "clouds": {"layers": [{"type": "cumulus", "coverage": 0.5, "base_m": 1500, "thickness_m": 1000, "seed": 7}]},
      "quality": {"samples_per_pixel": 2}, "output": {"half": false}, "seed": 5})";
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(json)));
  ASSERT_TRUE(setup.scene->refraction() && setup.scene->objects() && setup.scene->clouds());
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  Image image(setup.plan.width, setup.plan.height);
  const LocalRenderResult result = render_image(renderer, &image, 2);
  EXPECT_EQ(result.counters.nonfinite, 0u);
  EXPECT_EQ(result.counters.depth_limit, 0u);
  double sum = 0.0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const double L = image.luminance(x, y);
      EXPECT_TRUE(std::isfinite(L) && L >= 0.0) << x << ", " << y;
      sum += L;
    }
  EXPECT_GT(sum, 0.0);
}

}  // namespace
}  // namespace skyfarm

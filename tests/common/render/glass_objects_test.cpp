// Light through glass objects (material::Body::kSolid dielectrics) in the
// path tracer, against closed forms: a glass sphere in a white furnace
// (smooth, rough, dispersive), the caustic of a glass ball lens at its
// paraxial focal length, and the transmittance of a smooth glass slab with
// its internal reflections.  The objects are the analytic test spheres and
// boxes of tests/support.  Tolerances: 4 standard errors unless stated.
#include <gtest/gtest.h>

#include "tests/support/analytic_boxes.h"
#include "tests/support/analytic_spheres.h"
#include "tests/support/path_moments.h"
#include "tests/support/sun_specs.h"
#include "tests/support/thin_layer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <utility>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/material/fresnel.h"
#include "common/material/surface.h"
#include "common/render/radiance_probe.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {
namespace {

// A non-absorbing glass of constant index n (no dispersion).
material::SurfaceSpec glass(double n, double roughness = 0.0) {
  material::SurfaceSpec s;
  s.name = "test glass";
  s.custom = true;
  s.kind = material::MaterialKind::kDielectric;
  s.wavelengths_nm = {300.0, 900.0};
  s.n = {n, n};
  s.roughness_x = s.roughness_y = roughness;
  return s;
}

// Vacuum (a layer of 1e-12 /m), the sun at `sun_zenith`, black ground.
Scene vacuum(double sun_zenith, double observer_height) {
  return Scene::from_specs(testing::thin_hg_layer(1e-12, 1000.0, 0.0), testing::sun_spec(sun_zenith, 0.0),
                           Location{0, 0, observer_height}, std::nullopt, 360.0, 830.0);
}

// The white furnace: vacuum, a white ground, a uniform sky of radiance 1
// and no sun.  Nothing absorbs, so every direction sees radiance 1 (the
// glass's included: what enters a non-absorbing body leaves it).  The
// smooth glass is exact: its crossings carry no radiance factor, so no
// path is rouletted.
Scene furnace() {
  AtmosphereSpec spec = testing::thin_hg_layer(1e-12, 1000.0, 0.0);
  spec.ground_albedo = 1.0;
  Scene scene = Scene::from_specs(spec, testing::sun_spec(30.0, 0.0), Location{0, 0, 1.0}, std::nullopt, 400.0, 700.0);
  scene.sun_enabled = false;
  scene.environment_radiance = 1.0;
  return scene;
}

const glm::dvec3 kFurnaceCentre(0.0, 4.0, 0.2);

// Through the centre, off it, near the rim (grazing entry, long internal
// paths), and the sky beside it.
std::vector<glm::dvec3> furnace_directions() {
  return {glm::normalize(kFurnaceCentre), glm::normalize(kFurnaceCentre + glm::dvec3(0.5, 0, 0.3)),
          glm::normalize(kFurnaceCentre + glm::dvec3(0.0, 0, -0.9)),
          glm::normalize(kFurnaceCentre + glm::dvec3(0.97, 0, 0)), glm::normalize(glm::dvec3(0.3, 1.0, 0.8))};
}

TEST(GlassObjects, GlassSphereInTheFurnaceHasTheEnvironmentsRadiance) {
  for (double roughness : {0.0, 0.3}) {
    Scene scene = furnace();
    const material::Surface ball(glass(1.5, roughness));
    scene.set_objects(std::make_shared<testing::AnalyticSpheres>(
        scene.observer(), std::vector<testing::AnalyticSpheres::Sphere>{{kFurnaceCentre, 1.0, &ball}}));
    const std::vector<glm::dvec3> dirs = furnace_directions();
    const ProbeResult r = probe_radiance(scene, dirs, {450.0}, 4096, 5, 2);
    EXPECT_EQ(r.counters.nonfinite, 0u);
    for (std::size_t d = 0; d < dirs.size(); ++d) {
      EXPECT_NEAR(r.radiance[d][0], 1.0, 4.0 * r.standard_error[d][0] + 1e-6)
          << "roughness " << roughness << ", direction " << d;
      std::printf("roughness %.1f direction %zu: L %.4f +- %.4f\n", roughness, d, r.radiance[d][0],
                  r.standard_error[d][0]);
    }
  }
}

// A glass surface that does not bound a body (SurfaceHit::solid false: a
// sheet) stays opaque, as the ground: what it transmits is absorbed, so in
// the furnace a smooth one shows the environment times its Fresnel
// reflectance at the angle it is seen at, and nothing of the inside (the
// noise is the roulette of the reflected paths, which are down to F).
TEST(GlassObjects, GlassSheetIsOpaqueAndReflectsFresnel) {
  Scene scene = furnace();
  const material::Surface sheet(glass(1.5));
  testing::AnalyticSpheres::Sphere s{kFurnaceCentre, 1.0, &sheet};
  s.solid = false;
  scene.set_objects(std::make_shared<testing::AnalyticSpheres>(scene.observer(),
                                                               std::vector<testing::AnalyticSpheres::Sphere>{s}));
  const std::vector<glm::dvec3> dirs = {glm::normalize(kFurnaceCentre),
                                        glm::normalize(kFurnaceCentre + glm::dvec3(0.5, 0, 0.3))};
  const ProbeResult r = probe_radiance(scene, dirs, {450.0}, 4096, 5, 2);
  for (std::size_t d = 0; d < dirs.size(); ++d) {
    const glm::dvec3 o = -kFurnaceCentre;  // the observer from the centre
    const double b = glm::dot(o, dirs[d]), t = -b - std::sqrt(b * b - (glm::dot(o, o) - 1.0));
    const double cos_theta = -glm::dot(dirs[d], glm::normalize(o + t * dirs[d]));
    EXPECT_NEAR(r.radiance[d][0], material::fresnel_dielectric(cos_theta, 1.5), 4.0 * r.standard_error[d][0] + 1e-9)
        << "direction " << d;
  }
}

// A dispersive glass (BK7, n from 1.53 at 400 nm to 1.51 at 700 nm) seen
// with four different wavelengths per path: a refraction sends them apart,
// so the path keeps only its hero, whose light counts for all four (the
// film sums L_i / pdf_i).  In the furnace the film estimate is still 1; had
// the secondaries been dropped without renormalising the hero's MIS weight,
// it would be 1/4 through the glass.
TEST(GlassObjects, DispersiveGlassInTheFurnaceKeepsTheRadianceOverTheWavelengths) {
  for (double roughness : {0.0, 0.3}) {
    Scene scene = furnace();
    material::SurfaceSpec bk7;
    bk7.name = "bk7";
    bk7.roughness_x = bk7.roughness_y = roughness;
    const material::Surface ball(bk7);
    scene.set_objects(std::make_shared<testing::AnalyticSpheres>(
        scene.observer(), std::vector<testing::AnalyticSpheres::Sphere>{{kFurnaceCentre, 1.0, &ball}}));
    const VolumePathIntegrator integrator(scene);
    for (const glm::dvec3& view : furnace_directions()) {
      const int n = 4096;
      double sum = 0.0, sum2 = 0.0;
      PathCounters counters;
      for (int i = 0; i < n; ++i) {
        Sampler sampler(9, 0, static_cast<std::uint64_t>(i));
        SampledWavelengths wl;
        const double u = sampler.next();
        for (int k = 0; k < kWavelengthsPerPath; ++k) wl.lambda_nm[k] = 400.0 + 300.0 * std::fmod(u + 0.25 * k, 1.0);
        wl.pdf.fill(1.0);
        const SampledSpectrum L = integrator.radiance(Ray{scene.observer(), view}, wl, sampler, &counters);
        const double film = L.average();
        sum += film;
        sum2 += film * film;
      }
      EXPECT_EQ(counters.nonfinite, 0u);
      const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
      EXPECT_NEAR(mean, 1.0, 4.0 * se + 1e-6) << "roughness " << roughness;
      std::printf("bk7 roughness %.1f: film %.4f +- %.4f\n", roughness, mean, se);
    }
  }
}

// The smooth slab's transmittance at incidence theta: each crossing of a
// face transmits 1 - R (R the unpolarised Fresnel reflectance the renderer
// uses), and the light reflected back and forth inside adds
//   T = (1 - R)^2 sum_k R^(2k) = (1 - R)^2 / (1 - R^2) = (1 - R) / (1 + R).
// An index of 3 makes R (0.25 at normal incidence) large enough that the
// internal reflections' share stands well above the noise.  A horizontal
// slab 0.5 m thick, 100 m wide, 3.5 m above the observer, who
// looks up through it at a uniform sky of radiance 1 over a black ground
// (what the slab reflects down is lost): L = T.
TEST(GlassObjects, SmoothSlabTransmitsOneMinusROverOnePlusR) {
  for (double theta_deg : {0.0, 45.0}) {
    Scene scene = vacuum(30.0, 1.5);
    scene.sun_enabled = false;
    scene.environment_radiance = 1.0;
    const material::Surface slab(glass(3.0));
    scene.set_objects(std::make_shared<testing::AnalyticBoxes>(
        scene.observer(),
        std::vector<testing::AnalyticBoxes::Box>{{{0.0, 0.0, 3.5}, {50.0, 50.0, 0.25}, &slab}}));
    const double theta = theta_deg * kDegToRad;
    const glm::dvec3 view(std::sin(theta), 0.0, std::cos(theta));
    const ProbeResult r = probe_radiance(scene, {view}, {550.0}, 16384, 3, 2);
    EXPECT_EQ(r.counters.nonfinite, 0u);
    const double R = material::fresnel_dielectric(std::cos(theta), 3.0);
    const double T = (1.0 - R) / (1.0 + R);
    EXPECT_NEAR(r.radiance[0][0], T, 4.0 * r.standard_error[0][0] + 1e-9) << theta_deg;
    // Without the internal reflections: (1 - R)^2, further than the noise.
    EXPECT_GT(std::abs(r.radiance[0][0] - (1.0 - R) * (1.0 - R)), 4.0 * r.standard_error[0][0]) << theta_deg;
    std::printf("slab at %.0f deg: L %.5f +- %.5f, (1-R)/(1+R) %.5f, (1-R)^2 %.5f\n", theta_deg, r.radiance[0][0],
                r.standard_error[0][0], T, (1.0 - R) * (1.0 - R));
  }
}

// An independent geometric-optics trace of the same ball for the caustic
// test below: the radiance of the ground point at distance h below the
// centre of a ball (radius R, index n) under the sun at the zenith, over
// the open ground's, counting the light refracted in and out once (no
// internal reflection): (1 / Omega_sun) integral over the directions that
// meet the ball and leave it within the sun's disk of (1 - F_in)(1 - F_out)
// cos theta dw, by a fixed (0.5, golden-ratio) lattice of n_dirs directions
// uniform over the cone the ball subtends.
double ball_lens_ratio(double h, double R, double n, double alpha, int n_dirs) {
  const double cos_max = std::sqrt(1.0 - (R / h) * (R / h));
  const double omega = 2.0 * kPi * (1.0 - cos_max);
  const auto refract = [](const glm::dvec3& d, const glm::dvec3& facing, double eta) -> std::optional<glm::dvec3> {
    const double ci = -glm::dot(d, facing), s2t = (1.0 - ci * ci) / (eta * eta);
    if (s2t >= 1.0) return std::nullopt;
    return glm::normalize(d / eta + (ci / eta - std::sqrt(1.0 - s2t)) * facing);
  };
  double sum = 0.0;
  for (int i = 0; i < n_dirs; ++i) {
    const double u = (i + 0.5) / n_dirs, v = std::fmod(i * 0.6180339887498949, 1.0);
    const double ct = 1.0 - u * (1.0 - cos_max), st = std::sqrt(1.0 - ct * ct);
    const glm::dvec3 d(st * std::cos(2.0 * kPi * v), st * std::sin(2.0 * kPi * v), ct);
    const glm::dvec3 c(0.0, 0.0, h);
    const double b = glm::dot(d, c), disc = b * b - (h * h - R * R);
    if (disc <= 0.0) continue;
    const glm::dvec3 p = (b - std::sqrt(disc)) * d - c;  // from the centre
    const glm::dvec3 n1 = p / R;
    const auto d1 = refract(d, n1, n);
    if (!d1) continue;
    const glm::dvec3 p2 = p - 2.0 * glm::dot(p, *d1) * *d1;
    const glm::dvec3 n2 = p2 / R;
    const auto d2 = refract(*d1, -n2, 1.0 / n);
    if (!d2 || d2->z <= std::cos(alpha)) continue;
    sum += (1.0 - material::fresnel_dielectric(-glm::dot(d, n1), n)) *
           (1.0 - material::fresnel_dielectric(glm::dot(*d1, n2), 1.0 / n)) * ct;
  }
  return sum / n_dirs * omega / (kPi * std::sin(alpha) * std::sin(alpha));
}

// A glass ball is a lens: the sun at the zenith above a ball of radius R
// and index n is focused at the paraxial focal length f = n R / (2 (n - 1))
// below its centre (a thick lens whose principal planes pass through the
// centre).  Balls of R = 0.5 m, n = 1.5 (f = 0.75 m) hang with their centres
// at h = f times 0.8 ... 1.25 above a white ground, each 3 m from the next;
// the camera looks at the ground point under each.  The ball's shadow ray
// is blocked, so all that spot's light came through the glass, found by the
// ground's BSDF samples.  The axial caustic: a ball has strong spherical
// aberration, so the outer zones' rays cross the axis short of f and the
// paraxial focus is the caustic's far end.  Hence the brightest spot lies
// at most 10 % of f short of f, thousands of times brighter than the open
// ground (rho L_sun sin^2 alpha; the sun's image is blurred only by the
// disk, f alpha = 3.5 mm), and past f the light falls: at 1.05 f less than
// half of what it is at f.  (Measured: the peak at 0.95 f, 2700 times the
// open ground, 1600 at f, 320 at 1.05 f.)  Each spot also agrees with the
// independent trace above (ball_lens_ratio: one refraction in and one out)
// within 4 standard errors plus 3 % of the brightest spot, the light the
// trace leaves out (internal reflections) being a few % of a spot at most.
TEST(GlassObjects, GlassBallFocusesTheSunAtTheParaxialFocalLength) {
  const double n = 1.5, radius = 0.5, f = n * radius / (2.0 * (n - 1.0));
  AtmosphereSpec spec = testing::thin_hg_layer(1e-12, 1000.0, 0.0);
  spec.ground_albedo = 1.0;
  Scene scene = Scene::from_specs(spec, testing::sun_spec(0.0, 0.0), Location{0, 0, 3.0}, std::nullopt, 360.0, 830.0);
  const material::Surface ball(glass(n));
  const std::vector<double> heights = {0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.25};
  std::vector<testing::AnalyticSpheres::Sphere> balls;
  std::vector<glm::dvec3> dirs;
  for (std::size_t i = 0; i < heights.size(); ++i) {
    const glm::dvec3 ground(3.0 * (static_cast<double>(i) - 3.0), 10.0, -3.0);
    balls.push_back({ground + glm::dvec3(0.0, 0.0, heights[i] * f), radius, &ball});
    dirs.push_back(glm::normalize(ground));
  }
  dirs.push_back(glm::normalize(glm::dvec3(-15.0, 10.0, -3.0)));  // open ground, 6 m from the nearest ball
  scene.set_objects(std::make_shared<testing::AnalyticSpheres>(scene.observer(), balls));
  SampledWavelengths wl;
  wl.lambda_nm.fill(550.0);
  wl.pdf.fill(1.0);
  const double Le = scene.medium().path_coefficients(wl, &scene.sun()).sun_radiance[0];
  const double sin_alpha = std::sin(scene.sun().angular_radius_rad());
  const double open = Le * sin_alpha * sin_alpha;
  const ProbeResult r = probe_radiance(scene, dirs, {550.0}, 65536, 19, 2);
  EXPECT_EQ(r.counters.nonfinite, 0u);
  std::size_t brightest = 0;
  for (std::size_t i = 0; i < heights.size(); ++i) {
    std::printf("h/f %.2f: L / open ground %.2f +- %.2f\n", heights[i], r.radiance[i][0] / open,
                r.standard_error[i][0] / open);
    if (r.radiance[i][0] > r.radiance[brightest][0]) brightest = i;
  }
  const double alpha = scene.sun().angular_radius_rad();
  std::vector<double> traced;
  for (double h : heights) traced.push_back(ball_lens_ratio(h * f, radius, n, alpha, 400000));
  const double traced_peak = *std::max_element(traced.begin(), traced.end());
  for (std::size_t i = 0; i < heights.size(); ++i) {
    std::printf("h/f %.2f: traced %.0f\n", heights[i], traced[i]);
    EXPECT_NEAR(r.radiance[i][0] / open, traced[i], 4.0 * r.standard_error[i][0] / open + 0.03 * traced_peak)
        << "h/f " << heights[i];
  }
  std::printf("open ground: %.4f +- %.4f of rho L sin^2 alpha\n", r.radiance.back()[0] / open,
              r.standard_error.back()[0] / open);
  EXPECT_NEAR(r.radiance.back()[0], open, 4.0 * r.standard_error.back()[0] + 1e-3 * open);
  EXPECT_GE(heights[brightest], 0.9) << "the brightest spot is at h = " << heights[brightest] << " f";
  EXPECT_LE(heights[brightest], 1.0) << "the brightest spot is at h = " << heights[brightest] << " f";
  EXPECT_GT(r.radiance[brightest][0] - 4.0 * r.standard_error[brightest][0], 500.0 * open);
  const std::size_t at_f = 3, past_f = 4;
  ASSERT_DOUBLE_EQ(heights[at_f], 1.0);
  EXPECT_LT(r.radiance[past_f][0] + 4.0 * r.standard_error[past_f][0],
            0.5 * (r.radiance[at_f][0] - 4.0 * r.standard_error[at_f][0]));
}

// The sun seen through a rough glass ball (GGX, n 1.5, single-bounce at
// alpha 0.02 and 0.05, multiple-bounce at 0.05): the camera's path refracts
// into the ball at the front and meets the sun by NEE at the back (a
// transmission towards the outside from a vertex inside the body) or by
// sampling the back surface's BSDF.  Sun-only, BSDF-only and both MIS heuristics estimate the same
// radiance: the transmission NEE from inside is consistent with the BSDF's
// transmitted samples.  The ball is 5 m towards the sun (10 degrees up),
// the pixel a tenth of the radius off its centre.
using Moments = testing::PathMoments;
Moments moments(const Scene& scene, const glm::dvec3& view, SurfaceSunSampling strategy,
                SurfaceMisHeuristic heuristic, int n) {
  std::uint64_t nonfinite = 0;
  const Moments m = testing::path_moments(scene, view, strategy, heuristic, n, 23, &nonfinite);
  EXPECT_EQ(nonfinite, 0u);
  return m;
}

TEST(GlassObjects, SunThroughARoughGlassBallAgreesForSunOnlyBsdfOnlyAndMis) {
  for (const auto& [alpha, multiple_bounce] : {std::pair{0.02, false}, std::pair{0.05, false}, std::pair{0.05, true}}) {
    Scene scene = vacuum(80.0, 1.5);
    material::SurfaceSpec spec = glass(1.5, alpha);
    spec.multiple_bounce = multiple_bounce;
    const material::Surface rough(spec);
    const glm::dvec3 centre = 5.0 * scene.sun().direction();
    scene.set_objects(std::make_shared<testing::AnalyticSpheres>(
        scene.observer(), std::vector<testing::AnalyticSpheres::Sphere>{{centre, 1.0, &rough}}));
    const glm::dvec3 view = glm::normalize(centre + glm::dvec3(0.1, 0.0, 0.0));
    const int n = 40000;
    const Moments sun = moments(scene, view, SurfaceSunSampling::kSunOnly, SurfaceMisHeuristic::kBalance, n);
    const Moments bsdf = moments(scene, view, SurfaceSunSampling::kBsdfOnly, SurfaceMisHeuristic::kBalance, n);
    const Moments balance = moments(scene, view, SurfaceSunSampling::kMis, SurfaceMisHeuristic::kBalance, n);
    const Moments power = moments(scene, view, SurfaceSunSampling::kMis, SurfaceMisHeuristic::kPower, n);
    const auto se = [n](const Moments& m) { return std::sqrt(m.variance / n); };
    ASSERT_GT(sun.mean, 0.0) << alpha;
    const char* model = multiple_bounce ? "multiple bounce" : "single bounce";
    EXPECT_NEAR(bsdf.mean, sun.mean, 4.0 * std::hypot(se(bsdf), se(sun))) << "alpha " << alpha << ", " << model;
    EXPECT_NEAR(balance.mean, sun.mean, 4.0 * std::hypot(se(balance), se(sun))) << "alpha " << alpha << ", " << model;
    EXPECT_NEAR(power.mean, sun.mean, 4.0 * std::hypot(se(power), se(sun))) << "alpha " << alpha << ", " << model;
    std::printf("through glass, alpha %.2f%s: L sun %.4g, BSDF %.4g, balance %.4g, power %.4g; variance %.3g, %.3g, "
                "%.3g, %.3g\n",
                alpha, multiple_bounce ? " (multiple bounce)" : "", sun.mean, bsdf.mean, balance.mean, power.mean, sun.variance, bsdf.variance, balance.variance,
                power.variance);
  }
}

}  // namespace
}  // namespace skyfarm

// The ground as a material in the path tracer, against oracles that do not
// use the renderer: the Fresnel equations for a smooth water surface, a
// quadrature of the BSDF over the sun's disk for rough surfaces (both MIS
// strategies at work), and the white furnace for a non-absorbing rough
// diffuse ground.  Tolerances: 4 standard errors of the estimate unless
// stated.
#include <gtest/gtest.h>

#include "tests/support/sun_specs.h"
#include "tests/support/thin_layer.h"

#include <cmath>
#include <complex>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/material/material_library.h"
#include "common/material/rough_conductor.h"
#include "common/material/surface.h"
#include "common/render/radiance_probe.h"
#include "common/render/volume_path_integrator.h"
#include "common/sampling/warps.h"

namespace skyfarm {
namespace {

// An atmosphere that is all but vacuum (optical depth 1e-9): what the
// ground reflects is the sun alone.
AtmosphereSpec vacuum_over(const material::SurfaceSpec& ground) {
  AtmosphereSpec spec = testing::thin_hg_layer(1e-12, 1000.0, 0.0);
  spec.ground_material = ground;
  return spec;
}

material::SurfaceSpec named(const char* name, double roughness, bool multiple_bounce = true) {
  material::SurfaceSpec s;
  s.name = name;
  s.kind = material::named_material(name).kind();
  s.roughness_x = s.roughness_y = roughness;
  s.multiple_bounce = multiple_bounce;
  return s;
}

// The unpolarised Fresnel reflectance of a dielectric of index n under air,
// from Snell's law and the s and p amplitudes (Born & Wolf, section 1.5).
double fresnel_water(double cos_i, double n) {
  const double sin_t = std::sqrt(1.0 - cos_i * cos_i) / n;
  const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const double rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  const double rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// The ground's normal where the ray from the observer along `view` meets it.
glm::dvec3 ground_normal_seen(const Scene& scene, const glm::dvec3& view) {
  const Ray ray{scene.observer(), view};
  const double R = scene.atmosphere().planet_radius_m();
  const double b = glm::dot(ray.o, ray.d), c = glm::dot(ray.o, ray.o) - R * R;
  return glm::normalize(ray.at(-b - std::sqrt(b * b - c)));
}

SampledSpectrum sun_radiance(const Scene& scene, const std::vector<double>& lambdas) {
  SampledWavelengths wl;
  for (int i = 0; i < kWavelengthsPerPath; ++i) wl.lambda_nm[static_cast<std::size_t>(i)] = lambdas[static_cast<std::size_t>(i)];
  wl.pdf.fill(1.0);
  return scene.medium().path_coefficients(wl, &scene.sun()).sun_radiance;
}

// The sun seen in a smooth water ground: the camera looks as far below the
// horizon as the sun is above it, towards the sun, so every path's mirror
// direction lies inside the disk (the ground's curvature over the 57 m to
// the reflection point turns it by 2e-5 rad, the disk's radius is 4.7e-3).
TEST(SurfaceGround, SmoothWaterShowsTheSunTimesItsFresnelReflectance) {
  const double sun_zenith = 80.0;
  const Scene scene = Scene::from_specs(vacuum_over(named("water", 0.0)), testing::sun_spec(sun_zenith, 0.0),
                                        Location{0, 0, 10.0}, std::nullopt, 360.0, 830.0);
  ASSERT_NE(scene.ground_surface(), nullptr);
  const std::vector<double> lambdas = {400.0, 500.0, 600.0, 700.0};
  const glm::dvec3 view = direction_from_zenith_azimuth((180.0 - sun_zenith) * kDegToRad, 0.0);
  const ProbeResult r = probe_radiance(scene, {view}, lambdas, 64, 3, 1);
  EXPECT_EQ(r.counters.nonfinite, 0u);
  const SampledSpectrum Le = sun_radiance(scene, lambdas);
  // The incidence angle at the reflection point, whose normal the ground's
  // curvature turns by 9e-6 rad from the observer's (F changes by 5e-5 there).
  const double cos_i = glm::dot(-view, ground_normal_seen(scene, view));
  for (std::size_t w = 0; w < lambdas.size(); ++w) {
    const double n = material::named_material("water").ior().n(lambdas[w]);
    const double expected = fresnel_water(cos_i, n) * Le[static_cast<int>(w)];
    EXPECT_NEAR(r.radiance[0][w], expected, 1e-6 * expected + 4.0 * r.standard_error[0][w]) << lambdas[w] << " nm";
  }
  // Off the glint the smooth surface shows the (empty) sky: nothing.
  const ProbeResult off = probe_radiance(scene, {direction_from_zenith_azimuth(100.0 * kDegToRad, 0.5)}, lambdas, 16, 3, 1);
  for (double L : off.radiance[0]) EXPECT_LT(L, 1e-6 * Le[0]);
}

// The integral over the sun's cone of g(wi) dwi, wi in the ground's local
// frame, by a polar midpoint rule on the cone (the disk is uniform).
template <class G>
double integral_over_the_disk(const Sun& sun, const Frame& frame, int rings, int sectors, G&& g) {
  const double alpha = sun.angular_radius_rad();
  const Frame cone(sun.direction());
  double sum = 0.0;
  for (int a = 0; a < rings; ++a) {
    const double theta = (a + 0.5) / rings * alpha;
    for (int b = 0; b < sectors; ++b) {
      const double phi = (b + 0.5) / sectors * 2.0 * kPi;
      const glm::dvec3 wi = frame.to_local(
          cone.to_world({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}));
      if (wi.z <= 0.0) continue;
      sum += g(wi) * std::sin(theta) * (alpha / rings) * (2.0 * kPi / sectors);
    }
  }
  return sum;
}

// L(wo) = L_sun * integral over the sun's cone of f(wo, wi) cos(theta_i)
// dwi (64 x 64 nodes), with the BSDF's own deterministic f.
double glint_by_quadrature(const material::Bsdf& bsdf, const Frame& frame, const glm::dvec3& wo_local,
                           const Sun& sun, double Le) {
  material::RandomSequence unused(0);
  return Le * integral_over_the_disk(sun, frame, 64, 64, [&](const glm::dvec3& wi) {
           return bsdf.f(wo_local, wi, unused) * wi.z;
         });
}

// The same with the multiple-bounce gold, whose f is a random estimate: the
// quadrature averages 16 estimates per node of the BSDF as the path tracer
// evaluates it (the walk from the viewer's side, f(wi, wo)).  Its own noise,
// ~0.3 % over the disk, is inside the 1 % allowance.
TEST(SurfaceGround, MultipleBounceGoldGlintMatchesItsAveragedEstimateOverTheDisk) {
  const double sun_zenith = 60.0, alpha = 0.3;
  const std::vector<double> lambdas = {450.0, 550.0, 650.0, 750.0};
  const Scene scene = Scene::from_specs(vacuum_over(named("gold", alpha, true)), testing::sun_spec(sun_zenith, 0.0),
                                        Location{0, 0, 10.0}, std::nullopt, 360.0, 830.0);
  const glm::dvec3 view = direction_from_zenith_azimuth((180.0 - sun_zenith - 3.0) * kDegToRad, 0.05);
  const ProbeResult r = probe_radiance(scene, {view}, lambdas, 20000, 9, 2);
  EXPECT_EQ(r.counters.nonfinite, 0u);
  const glm::dvec3 n = ground_normal_seen(scene, view);
  const Frame frame(n);
  const SampledSpectrum Le = sun_radiance(scene, lambdas);
  constexpr int kRepeats = 16;
  for (std::size_t w = 0; w < lambdas.size(); ++w) {
    const material::SurfaceBsdf bsdf = scene.ground_surface()->bsdf(lambdas[w]);
    // Isotropic: any tangent frame about n gives the same values.
    const glm::dvec3 wo = frame.to_local(-view);
    material::RandomSequence rng(77);
    const double sum = integral_over_the_disk(scene.sun(), frame, 16, 32, [&](const glm::dvec3& wi) {
      double f = 0.0;
      for (int k = 0; k < kRepeats; ++k) f += bsdf.get().f(wi, wo, rng) / kRepeats;
      return f * wi.z;
    });
    const double expected = Le[static_cast<int>(w)] * sum;
    ASSERT_GT(expected, 0.0);
    EXPECT_NEAR(r.radiance[0][w], expected, 4.0 * r.standard_error[0][w] + 0.01 * expected) << lambdas[w] << " nm";
  }
}

// Sun NEE and BSDF sampling combined by MIS at a rough gold ground give the
// integral of the BSDF over the disk: a sharp lobe (alpha 0.02, the disk
// as wide as the lobe: both strategies matter) and a broad one.  The
// single-bounce form has a deterministic f to integrate.
TEST(SurfaceGround, RoughGoldGlintMatchesTheBsdfIntegratedOverTheSunsDisk) {
  const double sun_zenith = 60.0;
  const std::vector<double> lambdas = {450.0, 550.0, 650.0, 750.0};
  for (double alpha : {0.02, 0.3}) {
    const Scene scene = Scene::from_specs(vacuum_over(named("gold", alpha, false)), testing::sun_spec(sun_zenith, 0.0),
                                          Location{0, 0, 10.0}, std::nullopt, 360.0, 830.0);
    // Slightly off the mirror direction, so the lobe's slope matters too.
    const glm::dvec3 view = direction_from_zenith_azimuth((180.0 - sun_zenith - 0.8) * kDegToRad, 0.01);
    const ProbeResult r = probe_radiance(scene, {view}, lambdas, 20000, 5, 2);
    EXPECT_EQ(r.counters.nonfinite, 0u);
    // The reflection point and its frame, as the integrator finds them.
    const glm::dvec3 n = ground_normal_seen(scene, view);
    const glm::dvec3 east = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), n));
    Frame frame;
    frame.n = n;
    frame.s = east;
    frame.t = glm::cross(n, east);
    const SampledSpectrum Le = sun_radiance(scene, lambdas);
    for (std::size_t w = 0; w < lambdas.size(); ++w) {
      const material::RoughConductor gold(
          material::MicrofacetDistribution(material::MicrofacetModel::ggx, alpha, alpha),
          material::ConductorFresnel{material::named_material("gold").ior().at(lambdas[w]).eta(), false});
      const double expected = glint_by_quadrature(gold, frame, frame.to_local(-view), scene.sun(), Le[static_cast<int>(w)]);
      ASSERT_GT(expected, 0.0);
      EXPECT_NEAR(r.radiance[0][w], expected, 4.0 * r.standard_error[0][w] + 1e-3 * expected)
          << "alpha " << alpha << ", " << lambdas[w] << " nm";
    }
  }
}

// A non-absorbing rough diffuse ground (albedo 1, Lambertian microfacets)
// under a conservative atmosphere lit by a uniform environment: with
// multiple bounces every path's energy comes back, so the radiance is the
// environment's everywhere; the single-bounce form loses energy.
TEST(SurfaceGround, WhiteRoughDiffuseGroundInTheFurnaceReturnsTheEnvironment) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  ConstituentSpec air;
  air.name = "air";
  air.density = ExponentialDensity{8000.0};
  air.scattering_per_m = {{400.0, 700.0}, {3.0e-5, 6.0e-6}};
  air.phase = RayleighPhaseSpec{0.03};
  spec.constituents = {air};
  material::SurfaceSpec white;
  white.name = "white";
  white.custom = true;
  white.kind = material::MaterialKind::kDiffuse;
  white.wavelengths_nm = {400.0, 700.0};
  white.albedo = {1.0, 1.0};
  white.roughness_x = white.roughness_y = 1.0;
  const std::vector<glm::dvec3> dirs = {direction_from_zenith_azimuth(0.0, 0.0),
                                        direction_from_zenith_azimuth(120.0 * kDegToRad, 2.0),
                                        direction_from_zenith_azimuth(170.0 * kDegToRad, 0.3)};
  for (bool multiple : {true, false}) {
    white.multiple_bounce = multiple;
    spec.ground_material = white;
    Scene scene = Scene::from_specs(spec, testing::sun_spec(30.0, 0.0), Location{0, 0, 0.0}, std::nullopt, 400.0, 700.0);
    scene.sun_enabled = false;
    scene.environment_radiance = 1.0;
    const ProbeResult r = probe_radiance(scene, dirs, {420.0, 650.0}, 8192, 3, 2);
    EXPECT_EQ(r.counters.nonfinite, 0u);
    for (std::size_t d = 0; d < dirs.size(); ++d)
      for (std::size_t w = 0; w < 2; ++w) {
        if (multiple) {
          EXPECT_NEAR(r.radiance[d][w], 1.0, 4.0 * r.standard_error[d][w] + 1e-9) << "direction " << d;
        } else if (d > 0) {  // looking at the ground: the single bounce loses a few percent at alpha 1
          EXPECT_LT(r.radiance[d][w], 1.0 - 4.0 * r.standard_error[d][w]) << "direction " << d;
        }
      }
  }
}

// The LUT's stand-in for a material: the white-sky albedo.  A Lambertian
// material's is its albedo; a smooth dielectric's is the hemispherical
// average of the Fresnel reflectance, 2 integral F(mu) mu dmu (6.6 % for
// n = 1.333 by the same integral done here by a fine midpoint rule).
TEST(SurfaceGround, WhiteSkyAlbedoIsTheHemisphericalAverageOfTheReflectance) {
  const material::Surface snow(named("snow", 0.0));
  EXPECT_DOUBLE_EQ(snow.white_sky_albedo(500.0), material::named_material("snow").albedo().at(500.0));
  const material::Surface water(named("water", 0.0));
  const double n = material::named_material("water").ior().n(550.0);
  double integral = 0.0;
  constexpr int kSteps = 20000;
  for (int i = 0; i < kSteps; ++i) {
    const double mu = (i + 0.5) / kSteps;
    integral += 2.0 * fresnel_water(mu, n) * mu / kSteps;
  }
  EXPECT_NEAR(water.white_sky_albedo(550.0), integral, 1e-4);
  EXPECT_NEAR(integral, 0.066, 0.003);
}

}  // namespace
}  // namespace skyfarm

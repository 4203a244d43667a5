// Test support: a horizontally uniform cloud slab in an airless sky over a
// black ground, lit by a point sun, and its flux reflectance and
// transmittance as the path tracer gives them: the scenes of the cloud
// oracles (plane-parallel radiative transfer).
//
// Fluxes from radiance: an observer just above the slab (or below it) sends
// camera rays cosine-weighted over the lower (upper) hemisphere; the
// hemispherical flux is pi E[L], and R = pi E[L_up] / (mu0 E0), T_diffuse =
// pi E[L_down] / (mu0 E0), E0 the sun's irradiance at normal incidence.  The
// planet's radius makes the slab a shell; over the few kilometres the paths
// wander it is plane-parallel to ~1e-4.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>

#include "common/clouds/scene_clouds.h"
#include "common/clouds/uniform_cloud_slab.h"
#include "common/render/volume_path_integrator.h"
#include "common/sampling/warps.h"
#include "tests/support/sun_specs.h"
#include "tests/support/thin_layer.h"

namespace skyfarm::testing {

// Grey cloud optics with a Henyey-Greenstein phase function of asymmetry g,
// and with an isotropic one: the slabs' particles when the Mie phase is not the point.
inline CloudOptics hg_cloud_optics(double g, double albedo = 1.0) {
  CloudOptics o;
  o.albedo = albedo;
  o.phase = PhaseFunction::henyey_greenstein(g);
  o.asymmetry = g;
  return o;
}
inline CloudOptics isotropic_cloud_optics(double albedo = 1.0) {
  CloudOptics o;
  o.albedo = albedo;
  o.phase = PhaseFunction::isotropic();
  return o;
}

constexpr double kSlabBottom_m = 1000.0, kSlabTop_m = 2000.0, kSlabLambda_nm = 550.0;

// The slab of optical depth tau (vertical) between kSlabBottom_m and
// kSlabTop_m; the observer at `observer_altitude_m`; the sun at `sun_zenith_deg`.
// (Or between bottom_m and top_m.)
inline std::unique_ptr<Scene> cloud_slab_scene(double tau, CloudOptics optics, double sun_zenith_deg,
                                               double observer_altitude_m, double bottom_m = kSlabBottom_m,
                                               double top_m = kSlabTop_m) {
  // "Airless": a layer (10 km, or 1 km above the slab) whose scattering is 1e-15 per metre.
  auto scene = std::make_unique<Scene>(Scene::from_specs(thin_hg_layer(1e-15, std::max(10000.0, top_m + 1000.0), 0.0),
                                                         sun_spec(sun_zenith_deg, 0.0, 0.0),
                                                         Location{0.0, 0.0, observer_altitude_m}, std::nullopt,
                                                         500.0, 600.0));
  const double sigma = tau / (top_m - bottom_m);
  auto slab = std::make_shared<UniformCloudSlab>(scene->atmosphere().planet_radius_m(), bottom_m, top_m,
                                                 sigma, std::move(optics));
  scene->set_clouds(std::make_shared<SceneClouds>(std::vector<std::shared_ptr<const CloudField>>{slab}));
  return scene;
}

struct FluxEstimate {
  double mean = 0.0, se = 0.0;
  PathCounters counters;
};

// pi E[L] / (mu0 E0) over n camera rays cosine-weighted about +z (up) or -z.
inline FluxEstimate hemisphere_flux_ratio(const Scene& scene, bool looking_up, int n, std::uint64_t seed,
                                          IntegratorOptions options = {}) {
  const VolumePathIntegrator integrator(scene, options);
  SampledWavelengths wl;
  wl.lambda_nm.fill(kSlabLambda_nm);
  wl.pdf.fill(1.0);
  // (|mu0|: a sun below the horizon still gives a positive ratio.)
  const double mu0 = std::abs(scene.sun().direction().z);
  const double norm = 3.14159265358979323846 / (mu0 * scene.sun().irradiance(kSlabLambda_nm));
  FluxEstimate out;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(seed, 0, static_cast<std::uint64_t>(i));
    glm::dvec3 d = square_to_cosine_hemisphere({sampler.get(1u << 30), sampler.get((1u << 30) + 1)});
    if (!looking_up) d.z = -d.z;
    const double x = integrator.radiance(Ray{scene.observer(), d}, wl, sampler, &out.counters)[0] * norm;
    sum += x;
    sum2 += x * x;
  }
  out.mean = sum / n;
  out.se = std::sqrt(std::max(0.0, sum2 / n - out.mean * out.mean) / n);
  return out;
}

}  // namespace skyfarm::testing

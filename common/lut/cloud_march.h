// Clouds in the LUT renderer: a deterministic ray march through a scene's
// cloud fields, lit by the LUT sky and the sun, composited over the LUT sky.
// APPROXIMATE: a preview of what the path tracer computes exactly (its error
// against the path tracer is measured by `skyfarm-worker bench lut-clouds`,
// never assumed; README.md and docs/experiments/*-lut-clouds.md).
//
// The march (Hillaire 2016, "Physically based sky, atmosphere and cloud
// rendering in Frostbite", §5; Hillaire 2020):
//   * the view ray visits the clouds' majorant pieces only
//     (CloudField::for_each_majorant), so empty space costs nothing; a piece
//     of length l and majorant sigma_maj gets n = ceil(max(sigma_maj l /
//     kOpticalStep, l / kMaxStep_m)) midpoint steps, at most max_steps per ray
//     in all (one per piece once the budget is spent), and the march stops
//     once the view's transmittance is below min_transmittance;
//   * each step integrates a source J that is constant over the step
//     analytically (Hillaire 2016, energy-conserving integration):
//       L += T * albedo * J * (1 - exp(-sigma_t dt)),  T *= exp(-sigma_t dt);
//   * J = sum_{i < octaves} a^i p_i(cos theta) exp(-b^i tau_sun) E_sun T_air
//         + L_ambient(h),
//     Wrenninge's (2013) octaves for multiple scattering: octave i scatters
//     a^i of the light, sees b^i of the optical depth tau_sun towards the sun
//     and a phase function c^i as eccentric (here p_i = c^i p + (1 - c^i) /
//     (4 pi), which for a Henyey-Greenstein p keeps the forward part's shape
//     and any tabulated phase works alike).  Octave 0 is exact single
//     scattering with the cloud's own phase function;
//   * tau_sun by a secondary march of sun_steps steps towards the sun, each
//     twice as long as the one before (Schneider 2015), over the distance
//     to the clouds' top shell along the sun direction: short steps resolve
//     the cloud's edge near the point, long ones the rest of the layer;
//   * E_sun T_air: the sun's irradiance per bin times the air's transmittance
//     from the point towards the sun (LutSky::transmittance_to_top; 0 in the
//     planet's shadow);
//   * L_ambient(h): the sky's light on the cloud, isotropic, from the LUT sky
//     marched at the cloud layer's top (downwelling, upper hemisphere) and
//     bottom (upwelling: air and sunlit ground, lower hemisphere), both over
//     ambient_directions directions at the observer's location:
//       L_ambient(h) = (f Phi_down + (1 - f) Phi_up) / (4 pi),
//     Phi the radiance integrated over a hemisphere (sr), f the height
//     fraction of h in the clouds' altitude range (Hillaire 2016's height
//     gradient).  It ignores the cloud's own shadow on the ground and on the
//     sky above it.
// Compositing (Hillaire 2020 applies aerial perspective at the cloud's
// transmittance-weighted mean depth t_c):
//   L = L_air(0, t_c) + T_air(0, t_c) (L_cloud + T_cloud L_behind),
//   L_behind = (L_sky - L_air(0, t_c)) / T_air(0, t_c), so
//   L = T_cloud L_sky + (1 - T_cloud) L_air(0, t_c) + T_air(0, t_c) L_cloud,
// with L_sky the LUT sky's radiance along the view (the sun disk included:
// it lies behind the clouds).  Clouds are grey: T_cloud is the same in every
// bin.  Not modelled: the clouds' shadows on the air and the ground, light
// between clouds (beyond the octaves), clouds seen through other clouds'
// aerial perspective at other depths.
//
// The two-stream alternative (kTwoStream): the point is taken to lie in a
// horizontally uniform slab whose optical depth above it, seen from the sun,
// is mu0 tau_sun (the marched sun path, so that a cumulus's sunlit side is
// shallow whatever lies above it) and below it tau_down (a vertical march of
// sun_steps doubling steps down to the clouds' bottom), black below.  Its
// diffuse radiance I(mu) = I0 + mu I1 (Eddington) after delta scaling (Joseph,
// Wiscombe & Weinman 1976: tau' = (1 - g^2) tau, g' = g / (1 + g)) is solved
// in closed form (cloud_march.cpp).  J is then the scaled beam's single
// scattering, p exp(-(1 - g^2) tau_sun) (p's forward peak capped at the
// Eddington phase's (1 + 3 g') / (4 pi): the peak's light stays in the
// beam), plus the diffuse field seen through the true phase function,
// I0 + g mu_v I1, mu_v the cosine of the direction towards the camera to the
// local up.  It reproduces the slab's diffuse reflectance
// and transmittance (~1/(1 + 3/4 (1 - g) tau)), which the octaves miss by a
// factor of several for tau >~ 5 (docs/experiments/*-lut-clouds.md).
//
// Parameters (CloudMarchOptions)
//   multiple_scattering kTwoStream (default: the smaller error against the
//                      path tracer, docs/experiments/*-lut-clouds.md) or kOctaves
//   max_steps          view-ray steps (192: a cumulus layer seen slantwise
//                      crosses ~10-40 majorant pieces; 192 steps keep a
//                      256 x 256 frame within seconds on 2 cores and the
//                      steps in dense pieces near kOpticalStep)
//   sun_steps          secondary march steps towards the sun (6)
//   octaves            kOctaves: octaves (4; 1 = single scattering)
//   octave_a/_b/_c     scattering, extinction and eccentricity factors (0.5)
//   ambient            add L_ambient (true)
//   ambient_directions LUT sky marches per hemisphere for Phi (64)
//   min_transmittance  the march stops below it (1e-3)
#pragma once
#include <span>
#include <vector>

#include "common/clouds/scene_clouds.h"
#include "common/geometry/ray.h"
#include "common/lut/lut_sky.h"

namespace skyfarm {

// How the march approximates the light scattered more than once.
//   kOctaves    Wrenninge's octaves (above)
//   kTwoStream  single scattering (octave 0) plus the diffuse light of a
//               plane-parallel, conservative delta-Eddington slab through
//               the point (two_stream_diffuse below)
enum class CloudMultipleScattering { kOctaves, kTwoStream };

struct CloudMarchOptions {
  CloudMultipleScattering multiple_scattering = CloudMultipleScattering::kTwoStream;
  int max_steps = 192;
  int sun_steps = 6;
  int octaves = 4;
  double octave_a = 0.5, octave_b = 0.5, octave_c = 0.5;
  bool ambient = true;
  int ambient_directions = 64;
  double min_transmittance = 1e-3;
};

class CloudMarch {
 public:
  // Precomputes the ambient light (a few hundred LUT marches).  `sky` and
  // `clouds` must outlive this object.  Throws std::invalid_argument for bad
  // options.
  CloudMarch(const LutSky& sky, const SceneClouds& clouds, CloudMarchOptions options = {});

  struct Result {
    double transmittance = 1.0;  // grey T_cloud along [0, t_max]
    double mean_depth_m = -1.0;  // t_c, -1 when the ray meets no cloud
    int steps = 0;               // view-ray steps taken
  };
  // The clouds' radiance leaving towards ray.o along -ray.d (L_cloud, per bin,
  // not attenuated by the air in front) and their transmittance (per bin, all
  // equal) over [0, t_max]; ray planet-centred, unit direction.
  Result march(const Ray& ray, double t_max, std::span<double> L_cloud, std::span<double> T_cloud) const;

  // The LUT sky's radiance L_sky along `view_dir` from the observer (what
  // LutSky::radiance gave) with the clouds composited over it, in place.
  void composite(const glm::dvec3& view_dir, std::span<double> L_sky) const;

  // Phi_down at the clouds' top and Phi_up at their bottom, per bin (W m^-2 nm^-1).
  std::span<const double> ambient_down() const { return phi_down_; }
  std::span<const double> ambient_up() const { return phi_up_; }
  const CloudMarchOptions& options() const { return options_; }

 private:
  double sun_optical_depth(const glm::dvec3& p) const;
  double down_optical_depth(const glm::dvec3& p, double r) const;

  const LutSky& sky_;
  const SceneClouds& clouds_;
  CloudMarchOptions options_;
  std::vector<double> phi_down_, phi_up_;
  double R_ = 0.0;
};

}  // namespace skyfarm

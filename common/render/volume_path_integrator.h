// The reference spectral path tracer of the atmosphere.
//
// Per path: kWavelengthsPerPath wavelengths; free-flight distances sampled
// with the hero wavelength's per-shell majorant (delta tracking through the
// null-scattering formulation of Miller, Georgiev & Jarosz 2019, "A null-
// scattering path integral formulation of light transport"), and the other
// wavelengths carried by spectral MIS: r_u and r_l hold, per wavelength, the
// path pdf had that wavelength been the hero, relative to the hero's (pbrt-v4
// VolPathIntegrator).  At every real scattering
// vertex and ground hit: next-event estimation of the sun disk with
// transmittance by ratio tracking (with Russian roulette on small
// transmittance), combined with phase / BRDF sampling by MIS (balance
// heuristic) where both can reach the sun; multiple scattering of any order
// with Russian roulette on the throughput; Lambertian ground.
//
// Next-event estimation in expectation: in the medium, the sun is sampled at
// EVERY tentative collision, weighted by the probability P_s = sigma_s/sigma_maj
// (hero) that delta tracking would have made it a real scattering there,
// instead of only at the collisions it does choose to scatter at.  The
// expectation is the same (the choice's indicator replaced by its
// probability), the variance far lower in thin skies where most camera rays
// would otherwise cross the whole atmosphere without scattering.  Camera
// rays in thin air may also inflate their majorants so that they gather the
// sun at more points (max_camera_majorant_scale; off by default since the
// forced collisions below).
//
// Clouds (Scene::clouds(), scene_clouds.h): a grey medium added to the air.
// Each segment first samples the clouds' first real collision by delta
// tracking in the clouds alone; the air's tracking then runs up to it, so
// the nearer collision of the two independent media is the sum's (their
// transmittances multiply).  A cloud collision scatters by the cloud's
// phase function with sun NEE (scatter_in_cloud); every shadow ray
// multiplies in the clouds' ratio-tracked transmittance.  Grey clouds leave
// the spectral-MIS ratios unchanged.  Each cloud vertex also estimates the
// next cloud vertex's NEE along a direction drawn from the phase function
// about the sun's (the sun lobe, IntegratorOptions::cloud_sun_lobe; Buras &
// Mayer 2011), balanced against the path's own next vertex: a cloud's
// diffraction peak (half its scattered light within ~1 degree) is then met
// without the path having to arrive along the sun's direction by chance.
// A clear sky takes none of this code.
//
// Options:
//   max_depth         hard cap on scattering events (a cost bound; hits are
//                     counted in PathCounters::depth_limit so tests keep it 0)
//   rr_start_depth    Russian roulette on throughput from this depth on
//                     (below rr_threshold_in_shadow in the planet's shadow)
#pragma once
#include <cstdint>
#include <memory>
#include <optional>

#include "common/geometry/ray.h"
#include "common/render/atmosphere_medium.h"
#include "common/render/bent_path.h"
#include "common/render/residual_ratio_tracking.h"
#include "common/render/scene.h"
#include "common/render/sunlit_intervals.h"
#include "common/sampling/sampler.h"
#include "common/sampling/warps.h"
#include "common/spectrum/sampled_spectrum.h"

namespace skyfarm {

class PathMajorants;
class RadianceControl;
class ShadowGuide;

// How the sun's light reaches a surface vertex (a material ground, an
// object): by next-event estimation and BSDF sampling combined by MIS (the
// renderer's), or by one of them alone (the MIS tests compare the three).
enum class SurfaceSunSampling { kMis, kSunOnly, kBsdfOnly };
// The MIS weights at a surface vertex (SurfaceSunSampling::kMis): Veach's
// balance or power (exponent 2) heuristic between the sun's and the BSDF's
// samples (the .cpp, above sample_sun, derives the power heuristic in the
// spectral-MIS ratio form).  Medium vertices and the Lambertian ground
// always use the balance heuristic.
enum class SurfaceMisHeuristic { kBalance, kPower };

struct IntegratorOptions {
  int max_depth = 100000;
  // Russian roulette on the depth alone: from depth_rr_start on, a path goes
  // on with probability depth_rr_survival and survivors carry 1/survival.
  // Unbiased, and it bounds the expected cost of a walk that nothing else
  // stops (albedo 1 in a thick cloud: the throughput never falls) by
  // about depth_rr_start + 1/(1 - survival) scatterings, while the hard cap
  // (max_depth) is reached with probability survival^(max_depth -
  // depth_rr_start) ~ 1e-39.  No sky or object path comes near it (air x100:
  // ~250 events): their bytes are those of the old hard cap at 10000.  The
  // price is variance where the light needs longer walks: diffuse
  // transmission through optical depths of hundreds takes ~(tau (1 - g))^2 /
  // (1 - g) scatterings (docs/experiments/2026-12-07-thick-clouds.md).
  int depth_rr_start = 10000;
  double depth_rr_survival = 0.999;
  SurfaceSunSampling surface_sun_sampling = SurfaceSunSampling::kMis;
  SurfaceMisHeuristic surface_mis_heuristic = SurfaceMisHeuristic::kPower;
  int rr_start_depth = 2;
  // Russian roulette plays on a throughput below this at vertices in the
  // planet's shadow (1 elsewhere), and survivors carry it: a twilight path
  // scattering in the dark air is still on its way to the lit air, where
  // most of its value lies, and killing it at its throughput's odds made
  // the rare survivors the heavy tail of the image.  Day vertices never use
  // it (the same bytes).
  double rr_threshold_in_shadow = 0.25;
  // Camera rays whose majorants promise fewer than this many tentative
  // collisions inflate them (up to max_camera_majorant_scale) so that each
  // gathers the sun in expectation at about this many points (see the .cpp).
  // Off (scale 1): it paid before camera rays had a forced collision; with
  // one it only lowers the chance that the ray scatters on (the multiple
  // scattering), and without it the images are less noisy at equal samples
  // for slightly fewer instructions.
  double camera_target_collisions = 1.0;
  double max_camera_majorant_scale = 1.0;
  // Inflation of the (coarse) majorants on shadow rays: ratio tracking's
  // relative variance is about exp(tau / scale) - 1, so looser bounds trade
  // collisions for much less noise on long, grazing shadow rays; 4 is the
  // best of the scales measured (8 and 16 lose again to the extra
  // collisions).
  double shadow_majorant_scale = 4.0;
  // At each cloud vertex, a second estimate of the sun's light at the next
  // cloud collision, reached along a direction drawn from the cloud's phase
  // function about the sun's direction, combined by MIS with the path's own
  // next vertex (see the .cpp above scatter_in_cloud): the next NEE then
  // meets a cloud's diffraction peak without the rare alignment it needs
  // otherwise.  Off: the bytes of a renderer without it.
  bool cloud_sun_lobe = true;
  // Shadow rays and the sunlit-segment estimator's transmittances by residual
  // ratio tracking against a per-shell control extinction
  // (residual_ratio_tracking.h) instead of ratio tracking with the coarse
  // majorants x shadow_majorant_scale (which then no longer applies).
  bool residual_ratio_tracking = true;
  // ... on shadow rays whose cosine to the local zenith is below this (air
  // mass above ~3): on short shadow rays plain ratio tracking through the 9
  // coarse shells is as good and cheaper than crossing ~40 fine shells.
  double residual_tracking_below_cos = 0.35;
  // ... and on shadow rays that start below this altitude, whatever their
  // angle: they cross the aerosol layer (scale height ~1.2 km), where the
  // coarse shells' majorants are loosest.  The ground's sun NEE is most of
  // the bright lower half of a ground-level panorama, and the image error is
  // luminance-weighted, so these rays matter more than their share of
  // directions.
  double residual_tracking_below_altitude_m = 3000.0;
  // The sun's scattered light from a sunlit-segment estimator on every
  // segment of the path (camera ray and each ray after a vertex), sampled in
  // the lit part of the segment (see the .cpp), instead of NEE at tentative
  // collisions.  Off by default: by day it lowers the error per sample a
  // little but costs about 1.5x the time per path.
  bool explicit_single_scattering = false;
  // ... on the segments the planet's shadow cuts or that start with the sun
  // below their local horizontal (twilight, and rays towards the dark side at
  // sunset): collisions rarely reach their sunlit part, or find the sun only
  // through long grazing air; the estimator samples the lit part alone.
  // Never at day (the same bytes as without).
  bool sunlit_segments_in_shadow = true;
  // At medium vertices in the planet's shadow, this share of the scattering
  // directions is drawn from a von Mises-Fisher lobe (kappa 10) aimed at the
  // sun's azimuth 5 deg above the local horizontal, where the lit air is
  // (twilight); the pdf is the mixture with the phase function's (MIS).
  double twilight_guide_fraction = 0.3;
  // Forced collisions on the path's first segments (0: none, 1: the camera
  // ray, 2: and the ray after the first vertex, ...): both "no tentative
  // collision along the whole segment" (weight T_maj) and "at least one"
  // (the first drawn within the segment) are followed (see the .cpp), so
  // every camera ray gathers the sun in the air.  The "none" branch is a
  // recursive call, so this also bounds the nesting.  8 costs about what 2
  // did (deeper segments mostly leave the atmosphere) and is less noisy;
  // more gains nothing.
  int forced_collision_segments = 8;
  // Russian roulette with a control variate (radiance_control.h) at vertices
  // outside the planet's shadow: a path that ends adds c, an approximation
  // of what the rest of it would have brought (the LUT sky's radiance
  // towards the next direction times the throughput); one that goes on adds
  // (X - c) / s.  Unbiased whatever c is; survival is raised where needed so
  // that no path's sum turns negative.  Null: plain roulette.  Built per job
  // when the sun is high enough for it to pay (RenderPlan::roulette_control).
  std::shared_ptr<const RadianceControl> roulette_control;
  // At medium vertices where the sun is below the local horizontal, this
  // share of the scattering directions is drawn from a table of the light
  // arriving there (shadow_guide.h: the LUT sky at the vertex's altitude and
  // sun angle, not the observer's), in place of the von Mises-Fisher lobe
  // above: from high vertices the lit air and the sun's aureole lie just
  // below the horizontal, where the lobe rarely sends a path.  The pdf is the
  // mixture with the phase function's.  Null: the lobe.  Built per job when
  // the sun is below the observer's horizon (RenderPlan::shadow_guide).
  //
  // What each option measured: docs/experiments/2026-11-22-path-tracer-
  // variance.md and docs/experiments/2026-12-02-twilight.md.
  std::shared_ptr<const ShadowGuide> shadow_guide;
  double shadow_guide_fraction = 0.3;
};

// Counters a renderer sums over its paths.
struct PathCounters {
  std::uint64_t paths = 0;
  std::uint64_t collisions = 0;    // tentative collisions (real + null), camera and shadow rays
  std::uint64_t nonfinite = 0;     // path results rejected by the NaN/Inf/negative firewall
  std::uint64_t depth_limit = 0;   // paths cut by max_depth
  void add(const PathCounters& o) {
    paths += o.paths;
    collisions += o.collisions;
    nonfinite += o.nonfinite;
    depth_limit += o.depth_limit;
  }
};

class VolumePathIntegrator {
 public:
  explicit VolumePathIntegrator(const Scene& scene, IntegratorOptions options = {});

  // Spectral radiance (W m^-2 sr^-1 nm^-1) arriving along -ray.d at ray.o, at
  // the path's wavelengths.  Always finite and >= 0 (the firewall zeroes and
  // counts anything else).
  SampledSpectrum radiance(const Ray& ray, const SampledWavelengths& lambda, Sampler& sampler,
                           PathCounters* counters) const;

  // An unbiased estimate of the transmittance between ray.o and ray.at(t_end)
  // at the path's wavelengths by ratio tracking, with the hero wavelength's
  // majorants (the air's without Russian roulette; the clouds', when the
  // scene has some, scene_clouds.h, with it): E[result_i] = exp(-tau_i).
  SampledSpectrum transmittance(const Ray& ray, double t_end, const SampledWavelengths& lambda, Sampler& sampler,
                                PathCounters* counters) const;

  const Scene& scene() const { return scene_; }

 private:
  // The same with the path's coefficients already looked up, and the
  // collision pattern's spectral-MIS pdf ratios (TrackedTransmittance::r_l).
  TrackedTransmittance tracked_transmittance(const Ray& ray, double t_end, const PathCoefficients& path,
                                             Sampler& sampler, PathCounters* counters) const;

 private:
  struct Vertex;
  struct SurfaceVertex;
  // What a path carries between vertices: throughput, spectral-MIS ratios
  // (r_u unidirectional, r_l light sampling; pbrt-v4), and how it got here.
  struct PathState {
    SampledSpectrum beta{1.0}, r_u{1.0}, r_l{1.0};
    bool mis_with_sun = false;           // the previous vertex sampled the sun (NEE)
    bool mis_power = false;              // ... with the power heuristic (a surface vertex)
    // The ray leaves a medium vertex whose segment's sun light came from the
    // sunlit-segment estimator (so the sun disk seen next is not counted).
    bool sun_from_segment_estimator = false;
    // The ray runs inside a solid object it entered by refraction (glass):
    // no atmosphere there (no collisions, no sun), and its segment ends on
    // the object's surface.  Set at every surface vertex from the side the
    // next direction leaves on; no other vertex is reached inside.
    bool in_solid = false;
    // The sun lobe's MIS weight for the NEE at the next vertex, when that is
    // a cloud collision at depth sun_lobe_depth (scatter_in_cloud).
    double sun_lobe_weight = 1.0;
    int sun_lobe_depth = -1;
    // With refraction: the sun's pdf over the directions at the segment's
    // start (apparent) over its pdf over the true directions it arrives
    // from, dw_true / dw_apparent (atmosphere_refraction.h); 1 without.
    double sun_pdf_scale = 1.0;
  };
  // What stays fixed along one path.
  struct PathContext {
    const SampledWavelengths& lambda;
    const PathCoefficients& path;
    const PathMajorants& fine;    // the path's rows of the medium's fine shells (segments)
    const PathMajorants& coarse;  // and of its coarse shells (shadow rays)
    const PathPhases& phases;
    Sampler& sampler;
    PathCounters* counters;
  };

 public:
  struct RayExtent;

 private:
  SampledSpectrum radiance_unchecked(const Ray& ray, const SampledWavelengths& lambda, Sampler& sampler,
                                     PathCounters* counters) const;
  SampledSpectrum trace(Ray ray, PathState st, int depth, const PathContext& c) const;
  bool scatter_in_medium(const glm::dvec3& p, const MediumPoint& mp, const PathPhases& phases, Sampler& sampler,
                         Ray* ray, PathState* st) const;
  // A real collision in a cloud at p: sun NEE, then the next direction.
  bool scatter_in_cloud(const CloudField& cloud, const glm::dvec3& p, const PathContext& c, int depth, Ray* ray,
                        PathState* st, SampledSpectrum* L) const;
  // The sun lobe's estimate from the cloud vertex at p (arrived along wo, the
  // phase function `phase`, the path's state st after the albedo).
  // s: the lobe's axis (the sun's direction, or its apparent one at p).
  SampledSpectrum sun_lobe_estimate(const PhaseFunction& phase, const glm::dvec3& s, const glm::dvec3& p,
                                    const glm::dvec3& wo, const PathState& st, const PathContext& c) const;
  // The extent of the bent path from ray.o along ray.d (traced into *path,
  // at the hero wavelength): the air, and the first object or cloud
  // collision met chord after chord.
  RayExtent bent_extent(const Ray& ray, const PathContext& c, BentPath* path) const;
  // The straight ray carrying the end of a bent path, and the extent in its
  // own distance (finish_segment's arguments).
  static void bent_tail(const BentPath& path, const RayExtent& extent, Ray* tail, RayExtent* tail_extent);
  // PathState::sun_pdf_scale of the segment from ray.o along ray.d.
  double sun_pdf_scale(const Ray& ray, const BentPath& path, const RayExtent& tail_extent,
                       const PathContext& c) const;
  bool finish_segment(const RayExtent& extent, const PathContext& c, int depth, Ray* ray, PathState* st,
                      SampledSpectrum* L) const;
  // A surface that is a material (the ground's when it is not Lambertian, an
  // object's) around a body (material::Body), its local frame's z the normal
  // on the ray's side or, for a solid that light crosses, the outward one:
  // sun NEE, then the next direction.  p_above and p_below are the surface
  // point already off the surface on either side of the frame's z: rays
  // leaving above start at p_above (and the sun's shadow rays), rays leaving
  // below at p_below (only a surface that light crosses has them).
  bool bounce_on_surface(const material::Surface& surface, material::Body body, const glm::dvec3& p_above,
                         const glm::dvec3& p_below, const Frame& frame, const PathContext& c, int depth, Ray* ray,
                         PathState* st, SampledSpectrum* L) const;
  // Russian roulette after the vertex at p whose next direction is wi (the
  // control variate adds to *L, the light this path has gathered so far).
  bool survives(PathState* st, const glm::dvec3& p, const glm::dvec3& wi, int depth, const PathContext& c,
                SampledSpectrum* L) const;
  bool in_planet_shadow(const glm::dvec3& p) const;
  bool residual_tracking_pays(const glm::dvec3& p, const glm::dvec3& wi) const;
  // The sunlit-segment estimate (without the path's throughput) and, per
  // wavelength, its sampling pdf had that wavelength been the hero over the
  // hero's (the point on the segment and both transmittances' collisions):
  // the caller adds beta L / avg(r_u r).
  // The twilight guide's axis at p (in the planet's shadow), or nothing.
  std::optional<glm::dvec3> twilight_guide(const glm::dvec3& p) const;
  const ShadowGuide* shadow_guide_at(const glm::dvec3& p) const;
  SampledSpectrum direction_pdf(const glm::dvec3& p, const glm::dvec3& wi, const SampledSpectrum& p_phase,
                                const ShadowGuide* table, const std::optional<glm::dvec3>& guide) const;
  struct SunlitSample {
    SampledSpectrum L{0.0}, r{1.0};
  };
  SunlitSample sunlit_single_scattering(const Ray& ray, double t0, double t1, const SunlitIntervals& lit,
                                        const PathCoefficients& path, const PathPhases& phases, Sampler& sampler,
                                        PathCounters* counters) const;
  // The camera ray's majorant inflation from its largest majorant optical depth.
  double camera_majorant_scale(double tau) const;
  SampledSpectrum sample_sun(const Vertex& v, const SampledWavelengths& lambda, Sampler& sampler,
                             PathCounters* counters) const;
  // Its shadow ray and weights with refraction: the bent path from v.p
  // along the apparent direction wi (pdf_light over the apparent directions).
  SampledSpectrum sample_sun_bent(const Vertex& v, const glm::dvec3& wi, double pdf_light, const SampledSpectrum& f,
                                  const SampledSpectrum& pdf_scatter, const SampledWavelengths& lambda,
                                  Sampler& sampler, PathCounters* counters) const;

  template <class Walk, class Line>
  bool ratio_track_shadow(Walk& walk, const Line& line, const Vertex& v, Sampler& sampler, PathCounters* counters,
                          SampledSpectrum* T_ray, SampledSpectrum* r_l_ray, SampledSpectrum* r_u_ray) const;
  SampledSpectrum weigh_sun(const Vertex& v, const SampledSpectrum& T_ray, const SampledSpectrum& r_l_ray,
                            const SampledSpectrum& r_u_ray, double pdf_light, const SampledSpectrum& f,
                            const SampledSpectrum& pdf_scatter) const;

  const Scene& scene_;
  IntegratorOptions options_;
};

}  // namespace skyfarm

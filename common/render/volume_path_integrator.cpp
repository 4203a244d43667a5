#include "common/render/volume_path_integrator.h"

#include "common/render/radiance_control.h"
#include "common/render/shadow_guide.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/core/math.h"
#include "common/geometry/sphere_intersection.h"
#include "common/material/surface.h"
#include "common/render/free_flight.h"
#include "common/render/lit_distance_sampler.h"
#include "common/render/recorded_shell_walk.h"
#include "common/render/residual_ratio_tracking.h"
#include "common/render/sunlit_intervals.h"
#include "common/sampling/warps.h"

namespace skyfarm {
namespace {

// Rays leaving the ground start this far above it, so a ray going up can
// never meet the sphere it starts on (a convex surface), whatever the round-off.
constexpr double kGroundOffset_m = 1e-6;
// The roulette control raises survival to at most this many times roulette's.
constexpr double kMaxRaise = 2.0;

}  // namespace

// Where a ray is in the atmosphere: [t_begin, t_end], and whether it ends on the ground.
struct VolumePathIntegrator::RayExtent {
  bool in_atmosphere = false;
  double t_begin = 0.0, t_end = 0.0;
  bool hits_ground = false;
  std::optional<SurfaceHit> object;  // an object before the ground or space (then t_end is its t)
  const CloudField* cloud = nullptr;  // a real collision in a cloud before them (then t_end is its t)
};

namespace {
using RayExtent = VolumePathIntegrator::RayExtent;

RayExtent ray_extent(const RadialRay& ray, const Atmosphere& atmosphere) {
  RayExtent e;
  const SphereHit top = intersect_sphere(ray, atmosphere.top_radius_m());
  const double t_ground = ground_distance(ray, atmosphere.planet_radius_m());
  e.hits_ground = t_ground >= 0.0;
  if (top.hit && top.t_far > 0.0) {
    e.in_atmosphere = true;
    e.t_begin = std::max(0.0, top.t_near);
    e.t_end = top.t_far;
  }
  if (e.hits_ground) e.t_end = t_ground;
  return e;
}

// The mixture phase function p_i(mu) = sum_s sigma_s,s(l_i) p_s(mu; l_i) / sigma_s(l_i).
SampledSpectrum mixture_phase(const MediumPoint& mp, const PathPhases& phases, double mu) {
  SampledSpectrum p(0.0);
  for (int s = 0; s < phases.count(); ++s) {
    const SampledSpectrum p_s = phases.eval(s, mu);
    for (int i = 0; i < kWavelengthsPerPath; ++i)
      if (mp.sigma_s_c[static_cast<std::size_t>(s)][i] > 0.0)
        p[i] += mp.sigma_s_c[static_cast<std::size_t>(s)][i] * p_s[i];
  }
  return safe_div(p, mp.sigma_s);
}

// An object's frame at the unit normal n (the side the ray came from): s
// along its tangent made perpendicular to n.
Frame surface_frame(const glm::dvec3& n, const glm::dvec3& tangent) {
  const glm::dvec3 s = tangent - glm::dot(tangent, n) * n;
  const double length = glm::length(s);
  if (!(length > 1e-12)) return Frame(n);
  Frame f;
  f.n = n;
  f.s = s / length;
  f.t = glm::cross(n, f.s);
  return f;
}

// The ground's local frame at the unit normal n: s towards the east (the
// anisotropic roughness_x axis), t towards the north, as at the observer
// (x east, y north, z up).  At the two points where east is undefined any
// frame will do: no camera looks there.
Frame ground_frame(const glm::dvec3& n) { return surface_frame(n, glm::cross(glm::dvec3(0.0, 1.0, 0.0), n)); }

// The seed of a BSDF's own random sequence for one stochastic evaluation:
// one of the path's numbers, so still a pure function of (job seed, pixel,
// sample, dimension).  Every wavelength's evaluation takes the same seed, so
// their estimates are correlated as the volume's are (material/bsdf.h).
std::uint64_t bsdf_seed(Sampler& sampler) { return static_cast<std::uint64_t>(sampler.next() * 0x1.0p53); }

// The power heuristic (exponent 2) in the spectral-MIS ratio form, for a
// path x that ends on the sun after a surface vertex.  Four wavelengths,
// each one's hero technique equally likely, and at the vertex two
// techniques per hero: the sun's sample (light, L) and the BSDF's (B).  The
// densities of x under the two families, over its wavelengths' heroes, are
// the mixtures
//   P_L(x) = (1/4) sum_k p_L,k(x),   P_B(x) = (1/4) sum_k p_B,k(x),
// and pbrt-v4's ratios are them over a reference density p_ref (the hero's
// density of the path up to the vertex times the hero's technique's at it):
//   avg(r_l) = P_L / p_ref,   avg(r_u) = P_B / p_ref.
// The hero is a one-sample choice among the four: a sample x drawn by the
// hero's technique of family s, weighed g(x) / P_s(x), has expectation
// integral g (the mixture's density is P_s), whatever the hero; the
// balance heuristic's f w_s / P_s with w_s = P_s / (P_L + P_B) is the
// integrator's beta f T Le / avg(r_l + r_u).  Both families sample once at
// every vertex, so any weights with w_L(x) + w_B(x) = 1 on every path keep
// the sum unbiased; the power heuristic's w_s = P_s^2 / (P_L^2 + P_B^2) are
// such weights, and the contribution of the family s that drew x is
//   F w_s / P_s = F P_s / (P_L^2 + P_B^2) = (F / p_ref) R_s / (R_L^2 + R_B^2),
// F / p_ref the path's throughput times the sun's radiance (the balance
// form's numerator) and R_L = avg(r_l), R_B = avg(r_u): the reference
// cancels, as it must.  The spectral combination stays the balance (the
// mixture over heroes: a one-sample choice), the heuristic between the two
// techniques becomes the power.  Each side computes R_L and R_B in its own
// reference (the NEE's at the vertex, the BSDF sample's where it meets the
// sun), which changes neither weight.  Returns R_s / (R_L^2 + R_B^2) for
// the family s whose ratio is r_s, scaled so that no square overflows.
double power_weight(double r_s, double r_other) {
  const double m = std::max(r_s, r_other);
  if (!(m > 0.0) || !std::isfinite(m)) return 0.0;
  const double a = r_s / m, b = r_other / m;
  return a / (m * (a * a + b * b));
}

}  // namespace

// A scattering vertex: in the medium (phase function) or on the ground (Lambert).
struct VolumePathIntegrator::Vertex {
  glm::dvec3 p;
  glm::dvec3 wo_propagation;  // direction the path arrived along
  bool on_ground = false;
  glm::dvec3 n;               // ground normal
  const MediumPoint* medium = nullptr;
  const PathPhases* phases = nullptr;
  const PathCoefficients* path = nullptr;
  const PathMajorants* shadow_majorants = nullptr;  // the coarse shells' rows
  SampledSpectrum beta, r_p;  // throughput and r_u of the path at the vertex
  const SurfaceVertex* surface = nullptr;  // a ground that is a material, not Lambertian
  const CloudField* cloud = nullptr;       // a scattering in a cloud (its phase function)
};

// A ground vertex on a surface that is a material: the local frame (s east,
// t north, n up), the direction back along the path in it, and the BSDF at
// each of the path's wavelengths.
struct VolumePathIntegrator::SurfaceVertex {
  Frame frame;
  glm::dvec3 wo;
  std::array<material::SurfaceBsdf, kWavelengthsPerPath> bsdf;
};

VolumePathIntegrator::VolumePathIntegrator(const Scene& scene, IntegratorOptions options)
    : scene_(scene), options_(options) {}

// The inflation must not depend on which wavelength is the hero: spectral MIS
// weighs each wavelength by the pdf its own hero technique would have had, so
// all four techniques must use the same majorants.  It is therefore set from
// the largest majorant optical depth of the path's wavelengths.
double VolumePathIntegrator::camera_majorant_scale(double tau) const {
  if (options_.max_camera_majorant_scale <= 1.0) return 1.0;
  if (tau * options_.max_camera_majorant_scale <= options_.camera_target_collisions)
    return options_.max_camera_majorant_scale;
  return std::max(1.0, options_.camera_target_collisions / tau);
}

SampledSpectrum VolumePathIntegrator::radiance(const Ray& ray, const SampledWavelengths& lambda, Sampler& sampler,
                                               PathCounters* counters) const {
  const SampledSpectrum L = radiance_unchecked(ray, lambda, sampler, counters);
  ++counters->paths;
  // The NaN/Inf firewall: nothing but finite, non-negative radiance reaches a film.
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    if (!std::isfinite(L[i]) || L[i] < 0.0) {
      ++counters->nonfinite;
      return SampledSpectrum(0.0);
    }
  }
  return L;
}

SampledSpectrum VolumePathIntegrator::radiance_unchecked(const Ray& ray, const SampledWavelengths& lambda,
                                                         Sampler& sampler, PathCounters* counters) const {
  const PathCoefficients path = scene_.medium().path_coefficients(lambda, &scene_.sun());
  const PathPhases phases = scene_.medium().phases(lambda);
  const PathMajorants fine(scene_.medium().fine_shells(), path.bins);
  const PathMajorants coarse(scene_.medium().coarse_shells(), path.bins);
  const PathContext c{lambda, path, fine, coarse, phases, sampler, counters};
  return trace(ray, PathState{}, 0, c);
}

// The path from `ray` on, `st` its state after `depth` vertices.
SampledSpectrum VolumePathIntegrator::trace(Ray ray, PathState st, int depth, const PathContext& c) const {
  const AtmosphereMedium& medium = scene_.medium();
  const Atmosphere& atmosphere = scene_.atmosphere();
  const PathCoefficients& path = c.path;
  const PathPhases& phases = c.phases;
  Sampler& sampler = c.sampler;
  PathCounters* counters = c.counters;
  SampledSpectrum L(0.0);
  // With the sunlit-segment estimator, the sun's light scattered in the
  // medium comes from sunlit_single_scattering on every segment of the path
  // (camera ray and every ray after a vertex), weighted by the path's
  // throughput; the delta-tracked path only carries the path on, so it
  // gathers no sun at its medium vertices and does not count the sun disk
  // seen right after one (that light is the segment estimator's).  Ground
  // vertices keep their NEE with MIS.
  MediumPoint mp;

  // With refraction, each segment outside solids is a bent path (bent_path.h):
  // its flight walks the chords, and finish_segment gets the straight ray
  // that carries the path's end (tail, tail_extent).
  const AtmosphereRefraction* refraction = scene_.refraction();
  BentPath bent_path;

  for (;; ++depth) {
    const bool bent = refraction && !st.in_solid;
    RayExtent extent;
    RadialRay radial{};
    if (bent) {
      extent = bent_extent(ray, c, &bent_path);
      if (bent_path.outcome == RefractedRay::Outcome::kTrapped) return L;  // circling in a duct: no light out
    } else {
      radial = radial_ray(ray);
      extent = ray_extent(radial, atmosphere);
      if (scene_.objects() && extent.in_atmosphere) {
        if ((extent.object = scene_.objects()->intersect(ray, extent.t_end))) {
          extent.t_end = extent.object->t;
          extent.hits_ground = false;
        }
      }
      // The clouds' first real collision on the segment (delta tracking in the
      // clouds alone, scene_clouds.h): the air's tracking below then runs up
      // to it, and the nearer of the two media's collisions is the sum's.
      if (scene_.clouds() && extent.in_atmosphere && !st.in_solid && extent.t_end > extent.t_begin) {
        if (const auto hit =
                scene_.clouds()->sample_collision(ray, extent.t_begin, extent.t_end, sampler, &counters->collisions)) {
          extent.t_end = hit->t;
          extent.hits_ground = false;
          extent.object.reset();
          extent.cloud = hit->field;
        }
      }
    }
    // The straight ray and extent finish_segment sees: the segment's own, or
    // the chord where the bent path ends (its exit direction if it escapes).
    Ray tail = ray;
    RayExtent tail_extent = extent;
    if (bent) bent_tail(bent_path, extent, &tail, &tail_extent);
    if (st.in_solid) {
      // Inside a solid object: straight to its surface, nothing in between.
      // A ray that misses it has slipped out through round-off: lost.
      if (!extent.object || !finish_segment(extent, c, depth, &ray, &st, &L)) return L;
      continue;
    }
    bool scattered = false, absorbed = false;
    // --- The sun scattered once along this segment, sampled where it is lit:
    // on segments the planet's shadow cuts or that start with the sun below
    // their local horizontal (or on every one if asked).
    bool explicit_single = false;
    // (Not on bent paths: its lit intervals and sun rays are straight lines;
    // the NEE at the collisions gathers that light instead.)
    if (scene_.sun_enabled && !bent && extent.in_atmosphere && extent.t_end > extent.t_begin &&
        (options_.explicit_single_scattering || options_.sunlit_segments_in_shadow)) {
      const SunlitIntervals lit = sunlit_intervals(ray, extent.t_begin, extent.t_end, scene_.sun().direction(),
                                                   atmosphere.planet_radius_m());
      explicit_single = options_.explicit_single_scattering || lit.shadowed ||
                        glm::dot(ray.o, scene_.sun().direction()) < 0.0;
      if (explicit_single) {
        const SunlitSample ss =
            sunlit_single_scattering(ray, extent.t_begin, extent.t_end, lit, path, phases, sampler, counters);
        if (!ss.L.is_zero()) L += st.beta * ss.L * (1.0 / (st.r_u * ss.r).average());
      }
    }

    // --- Through the medium: delta tracking with spectral MIS.
    if (extent.in_atmosphere && extent.t_end > extent.t_begin) {
      // The segment's majorant optical depth, once, for the camera ray's
      // inflation and the forced collision.
      // Those segments are walked twice (here and in the flight), so their
      // shell crossings are recorded and replayed.
      const bool forced = depth < options_.forced_collision_segments;
      const ShellMajorants& shells = medium.fine_shells();
      const ShellTraversal walk = bent ? ShellTraversal()
                                       : ShellTraversal(ray, radial, atmosphere.planet_radius_m(), shells.bottoms,
                                                        extent.t_begin, extent.t_end);
      std::optional<BentShellWalk> bent_walk;
      if (bent)
        bent_walk.emplace(bent_path, atmosphere.planet_radius_m(), shells.bottoms, extent.t_begin, extent.t_end);
      RecordedShellWalk record;
      SampledSpectrum tau_maj(0.0);
      if (bent && (depth == 0 || forced)) {
        BentShellWalk again = *bent_walk;
        tau_maj = majorant_optical_depth_along(again, c.fine);
      } else if (depth == 0 || forced) {
        record.record(walk);
        RecordedShellWalk::Replay replay = record.replay();
        tau_maj = majorant_optical_depth_along(replay, c.fine);
      }
      const double scale = depth == 0 ? camera_majorant_scale(tau_maj.max()) : 1.0;
      double forced_tau = 0.0;
      if (forced) {
        // --- Forced first collision on the first segments of the path (the
        // camera ray, the ray after the first vertex).  Their tentative
        // collisions split into "none" (weight T_maj of the whole segment,
        // with probability 1 for every hero: r_u unchanged, and r_l, the
        // sun-sampling technique's pdf over the actual one, times T_maj) and
        // "at least one" (the first drawn from the truncated exponential: the
        // actual pdf, and each wavelength's had it been the hero, divided by
        // 1 - T_maj).  Both are followed, so these rays always gather the
        // sun in the air and scatter on, instead of about 1 time in 10 in a
        // clear noon sky: the main source of multiple-scattering noise.
        const SampledSpectrum tau = tau_maj * scale;
        PathState none = st;
        none.beta *= exp_neg(tau);
        none.r_l *= exp_neg(tau);
        Ray next = tail;
        if (bent) none.sun_pdf_scale = sun_pdf_scale(ray, bent_path, tail_extent, c);
        if (finish_segment(tail_extent, c, depth, &next, &none, &L)) L += trace(next, none, depth + 1, c);
        SampledSpectrum p_some;
        for (int i = 0; i < kWavelengthsPerPath; ++i) p_some[i] = -std::expm1(-tau[i]);
        if (!(p_some[0] > 0.0)) return L;
        st.beta *= p_some[0];
        st.r_l *= p_some[0];
        st.r_u *= safe_div(SampledSpectrum(p_some[0]), p_some);
        forced_tau = tau[0];
      }
      const auto collide = [&](double, const glm::dvec3& p, const SampledSpectrum& sigma_maj,
                           const SampledSpectrum& T_maj_seg) {
        ++counters->collisions;
        const double p_absorb = mp.sigma_a[0] / sigma_maj[0];
        const double p_scatter = mp.sigma_s[0] / sigma_maj[0];
        // The sun gathered here in expectation: P_s times the NEE of the
        // real-scattering branch (throughput and r_u of that branch).
        if (scene_.sun_enabled && p_scatter > 0.0 && !explicit_single) {
          const double pdf = T_maj_seg[0] * mp.sigma_s[0];
          const SampledSpectrum beta_s = st.beta * T_maj_seg * mp.sigma_s * (1.0 / pdf);
          const SampledSpectrum r_u_s = st.r_u * T_maj_seg * mp.sigma_s * (1.0 / pdf);
          if (!beta_s.is_zero() && !r_u_s.is_zero()) {
            Vertex v{p, bent_walk ? bent_walk->direction() : ray.d, false, {}, &mp, &phases, &path, &c.coarse,
                     beta_s * p_scatter, r_u_s};
            L += sample_sun(v, c.lambda, sampler, counters);
          }
        }
        const double u = sampler.next();
        if (u < p_absorb) {
          absorbed = true;
          return false;
        }
        if (u < p_absorb + p_scatter) {
          // Real scattering: pdf of this event for the hero, T_maj sigma_s.
          const double pdf = T_maj_seg[0] * mp.sigma_s[0];
          st.beta *= T_maj_seg * mp.sigma_s * (1.0 / pdf);
          st.r_u *= T_maj_seg * mp.sigma_s * (1.0 / pdf);
          if (st.beta.is_zero() || st.r_u.is_zero()) {
            absorbed = true;
            return false;
          }
          if (bent_walk) ray.d = bent_walk->direction();  // the direction it arrived along
          scattered = scatter_in_medium(p, mp, phases, sampler, &ray, &st);
          absorbed = !scattered;
          return false;
        }
        // Null collision.
        const SampledSpectrum sigma_n = clamp_zero(sigma_maj - mp.sigma_a - mp.sigma_s);
        const double pdf = T_maj_seg[0] * sigma_n[0];
        if (!(pdf > 0.0)) {
          st.beta = SampledSpectrum(0.0);
          return false;
        }
        st.beta *= T_maj_seg * sigma_n * (1.0 / pdf);
        st.r_u *= T_maj_seg * sigma_n * (1.0 / pdf);
        st.r_l *= T_maj_seg * sigma_maj * (1.0 / pdf);
        return !st.beta.is_zero() && !st.r_u.is_zero();
      };
      const auto fly = [&](auto& segments) {
        return sample_t_maj_along(segments, c.fine, medium, ray, path, sampler, mp, collide, scale, forced_tau);
      };
      SampledSpectrum T_maj;
      if (bent_walk) {
        BentShellWalk& segments = *bent_walk;
        T_maj = sample_t_maj_along(segments, c.fine, medium, segments, path, sampler, mp, collide, scale, forced_tau);
      } else if (record.recorded()) {
        RecordedShellWalk::Replay replay = record.replay();
        T_maj = fly(replay);
      } else {
        ShellTraversal live = walk;
        T_maj = fly(live);
      }
      if (absorbed || st.beta.is_zero()) return L;
      if (!scattered) {
        const double T0 = T_maj[0];
        st.beta *= T_maj * (1.0 / T0);
        st.r_u *= T_maj * (1.0 / T0);
        st.r_l *= T_maj * (1.0 / T0);
      }
    }
    if (!scattered) {
      if (bent) st.sun_pdf_scale = sun_pdf_scale(ray, bent_path, tail_extent, c);
      ray = tail;
      if (!finish_segment(tail_extent, c, depth, &ray, &st, &L)) return L;
      continue;
    }
    st.mis_with_sun = scene_.sun_enabled && !scene_.sun().is_point();
    st.mis_power = false;
    st.sun_from_segment_estimator = explicit_single;
    if (!survives(&st, ray.o, ray.d, depth, c, &L)) return L;
  }
}

// A real scattering in the medium at p: the next direction from the mixture
// phase function (a constituent picked by its share of sigma_s at the hero
// wavelength, then its phase function sampled); false if it has no pdf.
// Concentration and elevation of the twilight guide's lobe.
constexpr double kGuideKappa = 10.0;
constexpr double kGuideElevation_rad = 5.0 * kDegToRad;

// Whether the planet hides the sun's centre from p (the cylinder behind it).
bool VolumePathIntegrator::in_planet_shadow(const glm::dvec3& p) const {
  if (!scene_.sun_enabled) return false;
  const double ps = glm::dot(p, scene_.sun().direction()), R = scene_.atmosphere().planet_radius_m();
  return ps < 0.0 && glm::dot(p, p) - ps * ps < R * R;
}

// The shadow guide where it applies at p (the sun below p's horizontal), or null.
const ShadowGuide* VolumePathIntegrator::shadow_guide_at(const glm::dvec3& p) const {
  return options_.shadow_guide && options_.shadow_guide->covers(p) ? options_.shadow_guide.get() : nullptr;
}

std::optional<glm::dvec3> VolumePathIntegrator::twilight_guide(const glm::dvec3& p) const {
  if (!(options_.twilight_guide_fraction > 0.0) || !scene_.sun_enabled) return std::nullopt;
  if (!in_planet_shadow(p)) return std::nullopt;
  const glm::dvec3 s = scene_.sun().direction();
  const glm::dvec3 n = glm::normalize(p);
  const glm::dvec3 towards_sun = s - glm::dot(s, n) * n;  // the sun's azimuth on the local horizontal
  const double len = glm::length(towards_sun);
  if (!(len > 0.0)) return std::nullopt;
  return std::cos(kGuideElevation_rad) * (towards_sun / len) + std::sin(kGuideElevation_rad) * n;
}

// The pdf of direction wi at the medium vertex p, per wavelength: the phase
// function's p_phase mixed with the shadow guide's table or, without it, the
// twilight guide's lobe (each at its share of the directions).  One function
// for the sampling and the sun NEE's MIS, which must agree.
SampledSpectrum VolumePathIntegrator::direction_pdf(const glm::dvec3& p, const glm::dvec3& wi,
                                                    const SampledSpectrum& p_phase, const ShadowGuide* table,
                                                    const std::optional<glm::dvec3>& guide) const {
  if (table) {
    const double alpha = options_.shadow_guide_fraction;
    return p_phase * (1.0 - alpha) + SampledSpectrum(alpha * table->pdf(p, wi));
  }
  if (guide) {
    const double alpha = options_.twilight_guide_fraction;
    return p_phase * (1.0 - alpha) +
           SampledSpectrum(alpha * square_to_von_mises_fisher_pdf(clamp_cos(glm::dot(*guide, wi)), kGuideKappa));
  }
  return p_phase;
}

// A real scattering in the medium at p: the next direction from the mixture
// phase function (a constituent picked by its share of sigma_s at the hero
// wavelength, then its phase function sampled) or, in the planet's shadow,
// a share of the time from the twilight guide's lobe; the pdf is the
// mixture's (per wavelength, for the spectral MIS); false if it has none.
bool VolumePathIntegrator::scatter_in_medium(const glm::dvec3& p, const MediumPoint& mp, const PathPhases& phases,
                                             Sampler& sampler, Ray* ray, PathState* st) const {
  const ShadowGuide* table = shadow_guide_at(p);
  const std::optional<glm::dvec3> guide = table ? std::nullopt : twilight_guide(p);
  const double alpha = table ? options_.shadow_guide_fraction : guide ? options_.twilight_guide_fraction : 0.0;
  glm::dvec3 wi;
  if ((table || guide) && sampler.next() < alpha) {
    if (table) {
      const double u1 = sampler.next(), u2 = sampler.next(), u3 = sampler.next();
      wi = table->sample(p, u1, u2, u3);
    } else {
      const glm::dvec3 local = square_to_von_mises_fisher({sampler.next(), sampler.next()}, kGuideKappa);
      wi = glm::normalize(Frame(*guide).to_world(local));
      sampler.next();  // as many numbers as the phase branch
    }
  } else {
    double pick = sampler.next() * mp.sigma_s[0];
    int s = 0;
    while (s + 1 < phases.count() && pick >= mp.sigma_s_c[static_cast<std::size_t>(s)][0]) {
      pick -= mp.sigma_s_c[static_cast<std::size_t>(s)][0];
      ++s;
    }
    const double mu = clamp_cos(phases.sample_cos_theta(s, sampler.next()));
    const double phi = 2.0 * kPi * sampler.next();
    const double sin_theta = safe_sqrt(1.0 - mu * mu);
    wi = glm::normalize(Frame(ray->d).to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu}));
  }
  const SampledSpectrum p_mix = mixture_phase(mp, phases, clamp_cos(glm::dot(ray->d, wi)));
  const SampledSpectrum pdf = direction_pdf(p, wi, p_mix, table, guide);  // per wavelength, had it been the hero
  const double pdf_dir = pdf[0];
  if (!(pdf_dir > 0.0)) return false;
  st->r_l = st->r_u * (1.0 / pdf_dir);
  st->beta *= p_mix * (1.0 / pdf_dir);
  st->r_u *= pdf * (1.0 / pdf_dir);
  *ray = Ray{p, wi};
  return true;
}

// Objects and clouds are met chord after chord, in order: the first object
// hit, then the clouds' first collision before it (delta tracking in the
// clouds is memoryless, so sampling it chord by chord is sampling it along
// the whole path).
RayExtent VolumePathIntegrator::bent_extent(const Ray& ray, const PathContext& c, BentPath* path) const {
  scene_.refraction()->trace(ray.o, ray.d, c.lambda.lambda_nm[0], path);
  RayExtent e;
  e.in_atmosphere = path->in_atmosphere;
  if (!e.in_atmosphere) return e;
  e.t_begin = path->t_enter;
  e.t_end = path->t_end;
  e.hits_ground = path->outcome == RefractedRay::Outcome::kHitGround;
  if (scene_.objects()) {
    for (const Chord& chord : path->chords) {
      if (chord.t0 >= e.t_end) break;
      if (auto hit = scene_.objects()->intersect(chord.ray(), chord.length)) {
        e.t_end = chord.t0 + hit->t;
        e.object = std::move(hit);
        e.hits_ground = false;
        break;
      }
    }
  }
  if (scene_.clouds()) {
    for (const Chord& chord : path->chords) {
      const double a = std::max(0.0, e.t_begin - chord.t0), b = std::min(chord.length, e.t_end - chord.t0);
      if (chord.t0 >= e.t_end) break;
      if (!(b > a)) continue;
      if (const auto hit = scene_.clouds()->sample_collision(chord.ray(), a, b, c.sampler, &c.counters->collisions)) {
        e.t_end = chord.t0 + hit->t;
        e.hits_ground = false;
        e.object.reset();
        e.cloud = hit->field;
        break;
      }
    }
  }
  return e;
}

void VolumePathIntegrator::bent_tail(const BentPath& path, const RayExtent& extent, Ray* tail,
                                     RayExtent* tail_extent) {
  *tail_extent = extent;
  if (!path.in_atmosphere) {
    *tail = Ray{path.start, path.exit_direction};
    return;
  }
  double local_t = 0.0;
  *tail = path.ray_at(extent.t_end, &local_t);
  tail_extent->t_begin = 0.0;
  tail_extent->t_end = local_t;
  // Out through the top: on into space along the exit direction, the true
  // direction of whatever it sees (the sun disk, the environment).
  if (!extent.hits_ground && !extent.object && !extent.cloud) *tail = Ray{tail->at(local_t), path.exit_direction};
}

// Only a path that escapes into the sun disk needs it (finish_segment's MIS).
double VolumePathIntegrator::sun_pdf_scale(const Ray& ray, const BentPath& path, const RayExtent& tail_extent,
                                           const PathContext& c) const {
  if (!scene_.sun_enabled || tail_extent.hits_ground || tail_extent.object || tail_extent.cloud) return 1.0;
  if (!scene_.sun().contains(path.exit_direction)) return 1.0;
  const double ratio = scene_.refraction()->solid_angle_ratio_at(ray.o, ray.d, c.lambda.lambda_nm[0]);
  return ratio > 0.0 ? 1.0 / ratio : 1.0;
}

// The end of a segment the path crossed without scattering: space (the sun
// disk, with MIS if the last vertex sampled it, and the environment; the
// path ends: false) or the ground (sun NEE, then a cosine-weighted bounce:
// *ray and *st become the bounced path's, true if it goes on).  Light
// gathered is added to *L.
bool VolumePathIntegrator::finish_segment(const RayExtent& extent, const PathContext& c, int depth, Ray* ray,
                                          PathState* st, SampledSpectrum* L) const {
  const Sun& sun = scene_.sun();
  const PathCoefficients& path = c.path;
  if (st->beta.is_zero()) return false;
  if (extent.cloud) return scatter_in_cloud(*extent.cloud, ray->at(extent.t_end), c, depth, ray, st, L);
  if (extent.object) {
    // Two-sided: the side the ray came from; a solid that light crosses
    // keeps its outward normal (the ray may come from inside).
    const SurfaceHit& hit = *extent.object;
    const material::Body body = hit.solid ? material::Body::kSolid : material::Body::kOpaque;
    const glm::dvec3 n =
        hit.surface->transmits(body) || glm::dot(hit.n, ray->d) < 0.0 ? hit.n : -hit.n;
    return bounce_on_surface(*hit.surface, body, hit.p + n * hit.offset_m, hit.p - n * hit.offset_m,
                             surface_frame(n, hit.tangent), c, depth, ray, st, L);
  }
  if (!extent.hits_ground) {
    const bool sun_is_segment_estimators = st->sun_from_segment_estimator;
    if (scene_.sun_enabled && sun.contains(ray->d) && !sun_is_segment_estimators) {
      const SampledSpectrum& Le = path.sun_radiance;
      if (!st->mis_with_sun) {
        *L += st->beta * Le * (1.0 / st->r_u.average());
      } else {
        const SampledSpectrum r_l = st->r_l * (sun.pdf(ray->d) * st->sun_pdf_scale);
        if (st->mis_power)
          *L += st->beta * Le * power_weight(st->r_u.average(), r_l.average());
        else
          *L += st->beta * Le * (1.0 / (st->r_u + r_l).average());
      }
    }
    if (scene_.environment_radiance > 0.0)
      *L += st->beta * scene_.environment_radiance * (1.0 / st->r_u.average());
    return false;
  }
  if (scene_.ground_surface()) {
    const glm::dvec3 n = glm::normalize(ray->at(extent.t_end));
    const glm::dvec3 p = n * (scene_.atmosphere().planet_radius_m() + kGroundOffset_m);
    return bounce_on_surface(*scene_.ground_surface(), material::Body::kOpaque, p, p, ground_frame(n), c, depth, ray,
                             st, L);
  }
  // --- Lambertian ground: sun NEE, then cosine-weighted continuation.
  const Atmosphere& atmosphere = scene_.atmosphere();
  const glm::dvec3 n = glm::normalize(ray->at(extent.t_end));
  const glm::dvec3 p = n * (atmosphere.planet_radius_m() + kGroundOffset_m);
  Vertex v{p, ray->d, true, n, nullptr, nullptr, &path, &c.coarse, st->beta, st->r_u};
  if (scene_.sun_enabled) *L += sample_sun(v, c.lambda, c.sampler, c.counters);
  double pdf = 0.0;
  const glm::dvec3 wi = atmosphere.ground().sample_direction(n, c.sampler.next(), c.sampler.next(), &pdf);
  if (!(pdf > 0.0)) return false;
  // f cos / pdf = rho for Lambert (pdf = cos / pi).
  st->beta *= path.ground_albedo;
  st->r_l = st->r_u * (1.0 / pdf);
  st->mis_with_sun = scene_.sun_enabled && !sun.is_point();
  st->mis_power = false;
  st->sun_from_segment_estimator = false;
  *ray = Ray{p, wi};
  return survives(st, p, wi, depth, c, L);
}

// A real collision in a cloud at p: the grey single-scattering albedo
// weighs the path (an absorption the same at every wavelength), the sun's
// NEE with the cloud's phase function (balance heuristic against the phase
// sample), then the next direction sampled exactly from the phase function.
// The collision's distance pdf and the phase pdf are the same at every
// wavelength, so the spectral-MIS ratios r_u change by nothing here.
//
// The sun lobe.  A cloud's phase function puts about half of the scattered
// light in a diffraction peak ~1 degree wide (P(0) ~ 600/sr for 10 um
// droplets), which the NEE at a vertex meets only where the path arrives
// within ~1 degree of the sun's direction: with the phase sample alone a
// chance of ~2e-5 per vertex, and a heavy-tailed estimate.  The light
// scattered once more at the path's next vertex, when that is a cloud
// collision, is the integral over wi of
//   p(wo.wi) g(wi),   g(wi) = E[the NEE at the cloud collision along wi]
// (its collision and air transmittance included), which the NEE at the
// next vertex estimates with wi drawn from p(wo.wi) (technique A).
// Following Buras & Mayer (2011, JQSRT 112, 434: detector-directional
// importance sampling, the sun being a backward path's detector), a second
// technique B draws wi from the same phase function about the sun's
// direction s, q(wi) = p(s.wi), tracks to the clouds' first collision along
// it and takes the NEE there.  The two are combined by the balance
// heuristic in direction: A's NEE at the next vertex is weighed by
// p / (p + q) (PathState::sun_lobe_weight), B's estimate is
//   beta p(wo.wi) g / q * q / (p + q) = beta p g / (p + q),
// so both are bounded by beta min(p, q)-like products where g holds the peak
// p(wi.s): no heavy tail.  Their weights sum to 1 at every wi, whether or
// not the path goes on, so the sum is unbiased.  Unlike sampling the path's
// own next direction from a mixture (tried: docs/experiments), the path's
// throughput is untouched, so long walks in thick clouds do not degenerate.
// The vertices at which the sun's centre is below the planet's horizon
// skip B (A's weight is then 1).  The price: one cloud collision search, an
// air transmittance and a shadow ray more per cloud vertex.
bool VolumePathIntegrator::scatter_in_cloud(const CloudField& cloud, const glm::dvec3& p, const PathContext& c,
                                            int depth, Ray* ray, PathState* st, SampledSpectrum* L) const {
  const CloudOptics& optics = cloud.optics();
  const glm::dvec3 wo = ray->d;
  st->beta *= optics.albedo;
  if (st->beta.is_zero()) return false;
  if (scene_.sun_enabled) {
    Vertex v{p, wo, false, {}, nullptr, nullptr, &c.path, &c.coarse, st->beta, st->r_u};
    v.cloud = &cloud;
    const double w_A = st->sun_lobe_depth == depth ? st->sun_lobe_weight : 1.0;
    *L += sample_sun(v, c.lambda, c.sampler, c.counters) * w_A;
  }
  // The lobe's axis: the sun's direction, or with refraction its apparent
  // direction at p (where the cloud's diffraction peak meets the sun's light).
  glm::dvec3 s = scene_.sun().direction();
  bool lobe = options_.cloud_sun_lobe && scene_.sun_enabled;
  if (lobe && scene_.refraction()) {
    const auto apparent = scene_.refraction()->apparent_direction(p, s, c.lambda.lambda_nm[0]);
    lobe = apparent.has_value();
    if (apparent) s = apparent->direction;
  } else if (lobe) {
    lobe = ground_distance(radial_ray(Ray{p, s}), scene_.atmosphere().planet_radius_m()) < 0.0;
  }
  if (lobe) *L += sun_lobe_estimate(optics.phase, s, p, wo, *st, c);
  const glm::dvec3 wi = optics.phase.sample_direction(wo, c.sampler.next(), c.sampler.next());
  const double pdf = optics.phase.eval(clamp_cos(glm::dot(wo, wi)));
  if (!(pdf > 0.0)) return false;
  if (lobe) {
    st->sun_lobe_weight = pdf / (pdf + optics.phase.eval(clamp_cos(glm::dot(s, wi))));
    st->sun_lobe_depth = depth + 1;
  }
  // f / pdf = 1: beta and r_u unchanged; r_l the sun technique's pdf over this one.
  st->r_l = st->r_u * (1.0 / pdf);
  st->mis_with_sun = scene_.sun_enabled && !scene_.sun().is_point();
  st->mis_power = false;
  st->sun_from_segment_estimator = false;
  *ray = Ray{p, wi};
  return survives(st, p, wi, depth, c, L);
}

// Technique B of the sun lobe (above): wi from the phase function about the
// sun's direction, the clouds' first collision along it (delta tracking in
// the clouds, as the path's segments sample theirs), the air's transmittance
// up to it (ratio tracking: its spectral-MIS ratios r_l join the vertex's,
// as a shadow ray's do in sample_sun) and the NEE there: the path's
// throughput times p(wo.wi) / q(wi) (the direction's importance weight)
// times the balance weight q / (p + q), that is beta p / (p + q).
//
// With refraction the hop from p to the next cloud collision stays straight
// (over the few km between cloud vertices a ray strays < 1 m from its
// chord), while the path's own next segment is bent: the two techniques'
// transport differs by that much.
SampledSpectrum VolumePathIntegrator::sun_lobe_estimate(const PhaseFunction& phase, const glm::dvec3& s,
                                                        const glm::dvec3& p, const glm::dvec3& wo,
                                                        const PathState& st, const PathContext& c) const {
  const glm::dvec3 wi = phase.sample_direction(s, c.sampler.next(), c.sampler.next());
  const double q = phase.eval(clamp_cos(glm::dot(s, wi)));
  const double p_wo = phase.eval(clamp_cos(glm::dot(wo, wi)));
  if (!(q > 0.0) || !(p_wo > 0.0)) return SampledSpectrum(0.0);
  const Ray ray{p, wi};
  double t_end = ground_distance(radial_ray(ray), scene_.atmosphere().planet_radius_m());
  if (!(t_end >= 0.0)) t_end = std::numeric_limits<double>::infinity();
  const std::optional<SceneClouds::Collision> hit =
      scene_.clouds()->sample_collision(ray, 0.0, t_end, c.sampler, &c.counters->collisions);
  if (!hit) return SampledSpectrum(0.0);
  if (scene_.objects() && scene_.objects()->occluded(ray, hit->t)) return SampledSpectrum(0.0);
  const TrackedTransmittance T_air = tracked_transmittance(ray, hit->t, c.path, c.sampler, c.counters);
  if (T_air.T.is_zero()) return SampledSpectrum(0.0);
  const double w = hit->field->optics().albedo * p_wo / (p_wo + q);
  Vertex v{ray.at(hit->t), wi, false, {}, nullptr, nullptr, &c.path, &c.coarse, st.beta * T_air.T * w,
           st.r_u * T_air.r_l};
  v.cloud = hit->field;
  return sample_sun(v, c.lambda, c.sampler, c.counters);
}

// A surface that is a material (the ground, an object): sun NEE with MIS
// (unless the surface is smooth: a delta lobe the sun's samples never
// meet), then the next direction proposed by the hero wavelength's BSDF.
// Every wavelength's f is an unbiased estimate (stochastic for the
// multiple-bounce forms) and its pdf the deterministic density its own
// proposal would have had, so the spectral MIS ratios r_u are built from
// pdfs alone (material/bsdf.h says why that keeps MIS unbiased).
//
// Opaque bodies (the ground, sheets, every conductor and diffuse solid): the
// frame faces the ray, and a direction below the surface is light that
// entered it (a dielectric's transmission): absorbed, the path ends.
//
// A solid that light crosses (a glass object, material::Body::kSolid): the
// frame's z is the OUTWARD normal and wo is on either side (the BSDFs of a
// transmitting surface take wo inside: the relative index inverts).  A
// direction below leaves from p_below into the body, where the path meets
// nothing but the body's surface again (PathState::in_solid).  The sun's
// NEE is made towards directions above only (from p_above): one below
// would cross the body, which blocks it.  The crossings carry no radiance
// factor (n_wo/n_wi)^2 (material/surface.h): every path starts (the
// camera) and ends (the sun, the sky) outside the bodies, entering and
// leaving each through its surface, so the factors would cancel anyway.
//
// A smooth dielectric picks its lobe (reflect, refract) with the hero's
// Fresnel probability; each wavelength's weight and r_u take its own F
// (spectral MIS over the discrete choice).  A refraction whose index differs
// across the path's wavelengths sends each along its own direction
// (dispersion): the path can follow only the hero's, so the others end there
// (pbrt-v4's TerminateSecondary).  In this integrator's ratio form that is
// beta_i = 0 (their light from here on) and r_u,i = r_l,i = 0: the path's
// further vertices have density 0 under any other wavelength's technique,
// so the hero's MIS weight 1 / avg(r_u) becomes the 4 = 1 / (1/4) of a
// path only one technique could draw, and the light the hero gathers from
// here on counts for the whole tuple (as the wavelength pdf divided by 4
// does in pbrt-v4, where r_u is not zeroed; doing both would count it 4
// times, doing neither would weigh the hero as if the others could have
// drawn the path).  A dielectric whose index is the same at every
// wavelength of the path keeps them all.
//
// f is evaluated with its arguments swapped, f(wi, wo): the multiple-bounce
// walk starts on the viewer's side.  The height-correlated microsurface is
// not reciprocal (Wang et al. 2022, supplement §2.2): its energy is conserved
// for light arriving from one direction, integral f(wo, wi) |wo.z| dwo = 1,
// while a path tracer gathers integral f(wo, wi) |wi.z| dwi, which for white
// Lambertian facets at alpha 1 seen from 10 degrees off the normal is 0.935.
// Swapped, a non-absorbing ground under a uniform sky returns all its light
// to the camera, as any closed isothermal scene must.  The reciprocal forms
// (Lambertian, single-bounce conductor, the smooth reflector, dielectric
// reflection) are unchanged by the swap; a dielectric's transmission loses
// its radiance factor by it (the transposed radiance form is the flux
// form), as the smooth dielectric of a solid has none.
bool VolumePathIntegrator::bounce_on_surface(const material::Surface& surface, material::Body body,
                                             const glm::dvec3& p_above, const glm::dvec3& p_below,
                                             const Frame& frame, const PathContext& c, int depth, Ray* ray,
                                             PathState* st, SampledSpectrum* L) const {
  const Sun& sun = scene_.sun();
  const glm::dvec3& n = frame.n;
  const bool crosses = surface.transmits(body);
  SurfaceVertex sv;
  sv.frame = frame;
  sv.wo = sv.frame.to_local(-ray->d);
  if (crosses ? sv.wo.z == 0.0 : !(sv.wo.z > 0.0)) return false;
  for (int i = 0; i < kWavelengthsPerPath; ++i) sv.bsdf[i] = surface.bsdf(c.lambda.lambda_nm[i], body);
  const bool specular = sv.bsdf[0].specular();
  const SurfaceSunSampling strategy = options_.surface_sun_sampling;
  if (scene_.sun_enabled && !specular && strategy != SurfaceSunSampling::kBsdfOnly) {
    const Vertex v{p_above, ray->d, true, n, nullptr, nullptr, &c.path, &c.coarse, st->beta, st->r_u, &sv};
    *L += sample_sun(v, c.lambda, c.sampler, c.counters);
  }
  const double uc = c.sampler.next(), u0 = c.sampler.next(), u1 = c.sampler.next();
  const std::uint64_t seed = bsdf_seed(c.sampler);
  glm::dvec3 wi;
  if (const material::SmoothDielectric* glass = sv.bsdf[0].smooth_dielectric()) {
    material::RandomSequence unused(seed);
    const std::optional<material::BsdfSample> hero = glass->sample(sv.wo, uc, {u0, u1}, unused);
    if (!hero || !(hero->pdf > 0.0)) return false;
    const bool reflect = (hero->flags & material::kBsdfReflection) != 0;
    wi = hero->wi;
    bool dispersed = false;
    for (int i = 0; i < kWavelengthsPerPath; ++i) {
      const material::SmoothDielectric* own = sv.bsdf[i].smooth_dielectric();
      const std::optional<material::SmoothDielectric::Lobe> lobe = own->lobe(sv.wo, reflect);
      st->beta[i] *= lobe ? lobe->weight / hero->pdf : 0.0;
      st->r_u[i] *= lobe ? lobe->probability / hero->pdf : 0.0;
      dispersed = dispersed || (!reflect && own->eta() != glass->eta());
    }
    if (dispersed) {
      for (int i = 1; i < kWavelengthsPerPath; ++i) st->beta[i] = st->r_u[i] = st->r_l[i] = 0.0;
    }
    st->mis_with_sun = false;
  } else {
    const std::optional<glm::dvec3> proposed = sv.bsdf[0].propose(sv.wo, uc, {u0, u1});
    if (!proposed || !(crosses ? proposed->z != 0.0 : proposed->z > 0.0)) return false;
    wi = *proposed;
    if (specular) {
      // The same mirror direction whatever the hero: r_u unchanged; F per wavelength.
      for (int i = 0; i < kWavelengthsPerPath; ++i) {
        material::RandomSequence unused(seed);
        const std::optional<material::BsdfSample> s = sv.bsdf[i].get().sample(sv.wo, uc, {u0, u1}, unused);
        st->beta[i] *= s ? s->value : 0.0;
      }
      st->mis_with_sun = false;
    } else {
      SampledSpectrum f, pdf;
      for (int i = 0; i < kWavelengthsPerPath; ++i) {
        material::RandomSequence rng(seed);
        f[i] = sv.bsdf[i].get().f(wi, sv.wo, rng);
        pdf[i] = sv.bsdf[i].pdf(sv.wo, wi);
      }
      const double pdf_hero = pdf[0];
      if (!(pdf_hero > 0.0)) return false;
      st->r_l = st->r_u * (1.0 / pdf_hero);
      st->beta *= f * (std::abs(wi.z) / pdf_hero);
      st->r_u *= pdf * (1.0 / pdf_hero);
      st->mis_with_sun = scene_.sun_enabled && !sun.is_point() && strategy == SurfaceSunSampling::kMis;
      st->mis_power = options_.surface_mis_heuristic == SurfaceMisHeuristic::kPower;
    }
  }
  // Sun only: the disk met by the BSDF's direction is NEE's alone.
  st->sun_from_segment_estimator = strategy == SurfaceSunSampling::kSunOnly && !specular;
  st->in_solid = crosses && wi.z < 0.0;
  const glm::dvec3 p = st->in_solid ? p_below : p_above;
  const glm::dvec3 wi_world = glm::normalize(sv.frame.to_world(wi));
  *ray = Ray{p, wi_world};
  return survives(st, p, wi_world, depth, c, L);
}

// Russian roulette on the MIS-normalised throughput after the vertex at
// `depth` (at p, the path going on along wi), against 1 or, in the planet's
// shadow, the lower rr_threshold_in_shadow: a throughput beta below the
// threshold w survives with probability s = beta / w and becomes w; and,
// before it, the depth cap.  False ends the path.
//
// With the roulette control (outside the planet's shadow), c = beta L~(p, wi)
// with L~ the control's radiance towards wi: a path that ends adds c, one
// that goes on adds -c (1 - s) / s now and its rest X / s later, so the
// estimate of the rest is c + (X - c) / s, of mean E[X] for any c.  Paths
// are never negative: s is raised to at least c_i / (L_i + c_i) at each
// wavelength, L the light this path has gathered (at s = 1 nothing changes),
// but to at most kMaxRaise times the plain survival; beyond that c is
// clipped to L s / (1 - s) (still a fixed c: unbiased).  Without the cap,
// where the gathered light is small next to c (a dense haze, AOD 10, whose
// direct sun is gone) paths ran 4x as long for 3x less efficiency.
bool VolumePathIntegrator::survives(PathState* st, const glm::dvec3& p, const glm::dvec3& wi, int depth,
                                    const PathContext& c, SampledSpectrum* L) const {
  if (st->beta.is_zero()) return false;
  // The depth cap first: a path cut there must not have paid the control's
  // -c (1 - s) / s for a rest it never traces (bench efficiency --max-depth).
  if (depth + 1 >= options_.max_depth) {
    ++c.counters->depth_limit;
    return false;
  }
  if (depth + 1 >= options_.depth_rr_start) {
    if (c.sampler.next() >= options_.depth_rr_survival) return false;
    st->beta *= 1.0 / options_.depth_rr_survival;
  }
  const SampledSpectrum rr_beta = st->beta * (1.0 / st->r_u.average());
  const bool in_shadow = in_planet_shadow(p);
  const double w = in_shadow ? options_.rr_threshold_in_shadow : 1.0;
  if (depth + 1 >= options_.rr_start_depth && w > 0.0 && rr_beta.max() < w) {
    if (options_.roulette_control && !in_shadow) {
      SampledSpectrum c_rest = options_.roulette_control->radiance(p, wi, c.lambda) * rr_beta;
      const double s_plain = rr_beta.max() / w;
      double s = s_plain;
      for (int i = 0; i < kWavelengthsPerPath; ++i)
        if (c_rest[i] > 0.0) s = std::max(s, c_rest[i] / ((*L)[i] + c_rest[i]));
      if (s > kMaxRaise * s_plain) {  // c beyond what the light gathered so far allows: clip it
        s = kMaxRaise * s_plain;
        for (int i = 0; i < kWavelengthsPerPath; ++i) c_rest[i] = std::min(c_rest[i], (*L)[i] * s / (1.0 - s));
      }
      if (s < 1.0) {
        if (c.sampler.next() >= s) {
          *L += c_rest;
          return false;
        }
        *L = clamp_zero(*L - c_rest * ((1.0 - s) / s));  // >= 0 but for round-off
        st->beta *= 1.0 / s;
      }
    } else {
      const double q = std::max(0.0, 1.0 - rr_beta.max() / w);
      if (c.sampler.next() < q) return false;
      st->beta *= 1.0 / (1.0 - q);
    }
  }
  return true;
}

// Whether a shadow ray from p along wi is tracked by residual ratio tracking
// (IntegratorOptions: grazing rays, and rays that start in the low, dense
// air) rather than ratio tracking through the coarse shells.
bool VolumePathIntegrator::residual_tracking_pays(const glm::dvec3& p, const glm::dvec3& wi) const {
  const double r = glm::length(p);
  return glm::dot(p, wi) < options_.residual_tracking_below_cos * r ||
         r - scene_.atmosphere().planet_radius_m() < options_.residual_tracking_below_altitude_m;
}

// Ratio tracking of a shadow ray's transmittance T_ray along a walk of its
// shell segments, with the MIS ratios r_l (light sampling) and r_u
// (unidirectional) of the null collisions, Russian roulette once the
// MIS-weighted transmittance is small; all three end divided by the hero
// wavelength's majorant transmittance.  False when T_ray is 0.
template <class Walk, class Line>
bool VolumePathIntegrator::ratio_track_shadow(Walk& walk, const Line& line, const Vertex& v, Sampler& sampler,
                                              PathCounters* counters, SampledSpectrum* T_ray_out,
                                              SampledSpectrum* r_l_out, SampledSpectrum* r_u_out) const {
  SampledSpectrum& T_ray = *T_ray_out;
  SampledSpectrum& r_l_ray = *r_l_out;
  SampledSpectrum& r_u_ray = *r_u_out;
  const AtmosphereMedium& medium = scene_.medium();
  MediumPoint mp;
  const SampledSpectrum T_maj = sample_t_maj_along(
      walk, *v.shadow_majorants, medium, line, *v.path, sampler, mp,
      [&](double, const glm::dvec3&, const SampledSpectrum& sigma_maj, const SampledSpectrum& T_maj_seg) {
        ++counters->collisions;
        const SampledSpectrum sigma_n = clamp_zero(sigma_maj - mp.sigma_a - mp.sigma_s);
        const double pdf = T_maj_seg[0] * sigma_maj[0];
        T_ray *= T_maj_seg * sigma_n * (1.0 / pdf);
        r_l_ray *= T_maj_seg * sigma_maj * (1.0 / pdf);
        r_u_ray *= T_maj_seg * sigma_n * (1.0 / pdf);
        // Russian roulette once the MIS-weighted transmittance is small.
        const SampledSpectrum Tr = T_ray * (1.0 / (r_l_ray + r_u_ray).average());
        if (Tr.max() < 0.05) {
          const double q = 0.75;
          if (sampler.next() < q)
            T_ray = SampledSpectrum(0.0);
          else
            T_ray *= 1.0 / (1.0 - q);
        }
        return !T_ray.is_zero();
      },
      options_.shadow_majorant_scale);
  if (T_ray.is_zero()) return false;
  const double T0 = T_maj[0];
  T_ray *= T_maj * (1.0 / T0);
  r_l_ray *= T_maj * (1.0 / T0);
  r_u_ray *= T_maj * (1.0 / T0);
  return true;
}

// The sun's contribution through a shadow ray of transmittance T_ray: MIS of
// sun sampling (pdf_light) against the phase function or BSDF (pdf_scatter),
// the balance heuristic unless a surface asks otherwise.
SampledSpectrum VolumePathIntegrator::weigh_sun(const Vertex& v, const SampledSpectrum& T_ray,
                                                const SampledSpectrum& r_l_ray, const SampledSpectrum& r_u_ray,
                                                double pdf_light, const SampledSpectrum& f,
                                                const SampledSpectrum& pdf_scatter) const {
  const Sun& sun = scene_.sun();
  const SampledSpectrum& Le = v.path->sun_radiance;
  const SampledSpectrum r_l = v.r_p * r_l_ray * pdf_light;
  const SampledSpectrum Ld = v.beta * f * T_ray * Le;
  if (sun.is_point() || (v.surface && options_.surface_sun_sampling == SurfaceSunSampling::kSunOnly))
    return Ld * (1.0 / r_l.average());
  const SampledSpectrum r_u = v.r_p * r_u_ray * pdf_scatter;
  if (v.surface && options_.surface_mis_heuristic == SurfaceMisHeuristic::kPower)
    return Ld * power_weight(r_l.average(), r_u.average());
  return Ld * (1.0 / (r_l + r_u).average());
}

// Next-event estimation of the sun from a vertex (pbrt-v4 SampleLd, with
// per-wavelength scattering pdfs because the mixture phase depends on l):
//   L_d = beta f T L_sun / avg_i(r_p,i (pdf_light r_l,ray,i + pdf_scatter,i r_u,ray,i)),
// balance heuristic between sampling the sun and sampling the phase/BRDF
// (for a point sun only the former exists).
//
// With refraction the sun's sample is a true direction on the disk; the
// light leaves p along its apparent direction (atmosphere_refraction.h, at
// the hero wavelength), and the shadow ray follows the bent path from there
// (ratio tracking through the coarse shells chord by chord; residual
// tracking's control is built for straight rays).  The sun's pdf over the
// apparent directions is its pdf over the true ones over dw_apparent /
// dw_true (finish_segment's sun_pdf_scale, the other side of the MIS).
SampledSpectrum VolumePathIntegrator::sample_sun(const Vertex& v, const SampledWavelengths& lambda, Sampler& sampler,
                                                 PathCounters* counters) const {
  const Sun& sun = scene_.sun();
  const Atmosphere& atmosphere = scene_.atmosphere();
  const AtmosphereRefraction* refraction = scene_.refraction();
  const double u1 = sampler.next(), u2 = sampler.next();
  double pdf_light = 0.0;
  glm::dvec3 wi = sun.sample_direction(u1, u2, &pdf_light);
  if (refraction) {
    const auto apparent = refraction->apparent_direction(v.p, wi, lambda.lambda_nm[0]);
    if (!apparent) return SampledSpectrum(0.0);  // the planet hides it
    wi = apparent->direction;
    pdf_light /= apparent->solid_angle_ratio;
  }

  // Scattering value f and its sampling pdf for each wavelength.
  SampledSpectrum f, pdf_scatter;
  if (v.on_ground) {
    const double cos_theta = glm::dot(v.n, wi);
    if (cos_theta <= 0.0) return SampledSpectrum(0.0);
    if (v.surface) {
      const glm::dvec3 wi_local = v.surface->frame.to_local(wi);
      const std::uint64_t seed = bsdf_seed(sampler);
      for (int i = 0; i < kWavelengthsPerPath; ++i) {
        material::RandomSequence rng(seed);
        const material::Bsdf& bsdf = v.surface->bsdf[static_cast<std::size_t>(i)].get();
        f[i] = bsdf.f(wi_local, v.surface->wo, rng) * cos_theta;  // viewer-side walk: see bounce_on_surface
        pdf_scatter[i] = v.surface->bsdf[static_cast<std::size_t>(i)].pdf(v.surface->wo, wi_local);
      }
    } else {
      f = v.path->ground_albedo * (kInvPi * cos_theta);
      pdf_scatter = SampledSpectrum(cos_theta * kInvPi);
    }
  } else if (v.cloud) {
    f = SampledSpectrum(v.cloud->optics().phase.eval(clamp_cos(glm::dot(v.wo_propagation, wi))));
    pdf_scatter = f;
  } else {
    f = mixture_phase(*v.medium, *v.phases, clamp_cos(glm::dot(v.wo_propagation, wi)));
    const ShadowGuide* table = shadow_guide_at(v.p);  // (penumbra: the disk partly seen)
    pdf_scatter = direction_pdf(v.p, wi, f, table, table ? std::nullopt : twilight_guide(v.p));
  }
  if (f.is_zero()) return SampledSpectrum(0.0);

  if (refraction) return sample_sun_bent(v, wi, pdf_light, f, pdf_scatter, lambda, sampler, counters);

  // Shadow ray: blocked by the planet, else ratio tracking to the top.
  const Ray shadow{v.p, wi};
  const RadialRay radial = radial_ray(shadow);  // shared by the ground, the top and the shells
  if (ground_distance(radial, atmosphere.planet_radius_m()) >= 0.0) return SampledSpectrum(0.0);
  if (scene_.objects() && scene_.objects()->occluded(shadow, std::numeric_limits<double>::infinity()))
    return SampledSpectrum(0.0);
  // The clouds' transmittance first: deep in a cloud it is 0 after a
  // collision or two, and the air's tracking is then never paid for.
  double T_clouds = 1.0;
  if (scene_.clouds()) {
    T_clouds = scene_.clouds()->transmittance(shadow, 0.0, std::numeric_limits<double>::infinity(), sampler,
                                              &counters->collisions);
    if (!(T_clouds > 0.0)) return SampledSpectrum(0.0);
  }
  const SphereHit top = intersect_sphere(radial, atmosphere.top_radius_m());
  SampledSpectrum T_ray(T_clouds), r_u_ray(1.0), r_l_ray(1.0);
  if (top.hit && top.t_far > 0.0 && options_.residual_ratio_tracking &&
      residual_tracking_pays(v.p, wi)) {
    const TrackedTransmittance tracked =
        residual_ratio_tracking(scene_.medium(), shadow, radial, std::max(0.0, top.t_near), top.t_far, *v.path,
                                sampler, &counters->collisions, true);
    if (tracked.T.is_zero()) return SampledSpectrum(0.0);
    T_ray = tracked.T;
    r_u_ray = tracked.r_u;
    r_l_ray = tracked.r_l;
  } else if (top.hit && top.t_far > 0.0) {
    const AtmosphereMedium& medium = scene_.medium();
    const ShellMajorants& shells = medium.coarse_shells();
    ShellTraversal walk(shadow, radial, atmosphere.planet_radius_m(), shells.bottoms, std::max(0.0, top.t_near),
                        top.t_far);
    if (!ratio_track_shadow(walk, shadow, v, sampler, counters, &T_ray, &r_l_ray, &r_u_ray)) return SampledSpectrum(0.0);
  }

  return weigh_sun(v, T_ray, r_l_ray, r_u_ray, pdf_light, f, pdf_scatter);
}

// The bent shadow ray of sample_sun towards the apparent direction wi.
SampledSpectrum VolumePathIntegrator::sample_sun_bent(const Vertex& v, const glm::dvec3& wi, double pdf_light,
                                                      const SampledSpectrum& f, const SampledSpectrum& pdf_scatter,
                                                      const SampledWavelengths& lambda, Sampler& sampler,
                                                      PathCounters* counters) const {
  const AtmosphereMedium& medium = scene_.medium();
  thread_local BentPath path;
  scene_.refraction()->trace(v.p, wi, lambda.lambda_nm[0], &path);
  if (path.outcome != RefractedRay::Outcome::kEscaped) return SampledSpectrum(0.0);
  if (scene_.objects())
    for (const Chord& chord : path.chords)
      if (scene_.objects()->occluded(chord.ray(), chord.length)) return SampledSpectrum(0.0);
  double T_clouds = 1.0;
  if (scene_.clouds()) {
    for (const Chord& chord : path.chords) {
      T_clouds *= scene_.clouds()->transmittance(chord.ray(), 0.0, chord.length, sampler, &counters->collisions);
      if (!(T_clouds > 0.0)) return SampledSpectrum(0.0);
    }
  }
  SampledSpectrum T_ray(T_clouds), r_u_ray(1.0), r_l_ray(1.0);
  if (path.in_atmosphere) {
    BentShellWalk walk(path, scene_.atmosphere().planet_radius_m(), medium.coarse_shells().bottoms, path.t_enter,
                       path.t_end);
    if (!ratio_track_shadow(walk, walk, v, sampler, counters, &T_ray, &r_l_ray, &r_u_ray)) return SampledSpectrum(0.0);
  }
  return weigh_sun(v, T_ray, r_l_ray, r_u_ray, pdf_light, f, pdf_scatter);
}

// Single scattering of sunlight along a segment, sampled where the sun is
// visible:
//   L_ss = int_sunlit T(o, x_t) sigma_s(x_t) p(theta) T(x_t, sun) L_sun dt.
// The sunlit part of the segment is the line minus the planet's shadow
// (sunlit_intervals.h).  t is drawn there from the majorant's truncated
// exponential (lit_distance_sampler.h), in one sample of two: in the other
// from the part whose sun ray clears the ground by kClearAltitude_m (the
// atmosphere's own shadow: a sun ray grazing the dense low air arrives
// nearly extinguished, yet that is where the majorant puts most points).
// The mixture's pdf is the average of both (one-sample MIS, balance), at
// every wavelength for the spectral MIS; the transmittances are (residual)
// ratio-tracking estimates, the sun direction is sampled on the disk.
VolumePathIntegrator::SunlitSample VolumePathIntegrator::sunlit_single_scattering(
    const Ray& ray, double t0, double t1, const SunlitIntervals& lit, const PathCoefficients& path,
    const PathPhases& phases, Sampler& sampler, PathCounters* counters) const {
  constexpr double kClearAltitude_m = 20000.0;
  SunlitSample none;
  none.L = SampledSpectrum(0.0);
  const AtmosphereMedium& medium = scene_.medium();
  const double R = scene_.atmosphere().planet_radius_m();
  const glm::dvec3 s = scene_.sun().direction();
  const LitDistanceSampler in_lit(ray, lit, R, medium.fine_shells(), path.bins);
  const LitDistanceSampler in_clear(ray, sunlit_intervals(ray, t0, t1, s, R + kClearAltitude_m), R,
                                    medium.fine_shells(), path.bins);
  const double u_t = sampler.next(), u_s1 = sampler.next(), u_s2 = sampler.next(), u_pick = sampler.next();
  if (in_lit.empty()) return none;
  const double w_clear = in_clear.empty() ? 0.0 : 0.5;
  double t = -1.0;
  if (!(u_pick < w_clear ? in_clear.sample(u_t, &t) : in_lit.sample(u_t, &t))) return none;
  // pdf of t had each wavelength been the hero; the hero's is the estimator's.
  const SampledSpectrum pdf_t_all =
      in_lit.pdf(t) * (1.0 - w_clear) + (w_clear > 0.0 ? in_clear.pdf(t) * w_clear : SampledSpectrum(0.0));
  const double pdf_t = pdf_t_all[0];
  if (!(pdf_t > 0.0)) return none;
  const glm::dvec3 x = ray.at(t);
  MediumPoint mp;
  medium.point(glm::length(x) - R, path, &mp);
  if (mp.sigma_s.is_zero()) return none;
  // The sun: a direction on the disk, blocked by the planet or not.
  double pdf_light = 0.0;
  const glm::dvec3 wi = scene_.sun().sample_direction(u_s1, u_s2, &pdf_light);
  const Ray to_sun{x, wi};
  if (ground_distance(to_sun, R) >= 0.0) return none;
  if (scene_.objects() && scene_.objects()->occluded(to_sun, std::numeric_limits<double>::infinity())) return none;
  const SampledSpectrum p = mixture_phase(mp, phases, clamp_cos(glm::dot(ray.d, wi)));
  const TrackedTransmittance T_cam = tracked_transmittance(ray, t, path, sampler, counters);
  const TrackedTransmittance T_sun = tracked_transmittance(to_sun, 1e300, path, sampler, counters);
  // The camera side crosses no cloud (the segment ends at the clouds' first
  // collision); the sun side may.
  const double T_clouds =
      scene_.clouds() ? scene_.clouds()->transmittance(to_sun, 0.0, 1e300, sampler, &counters->collisions) : 1.0;
  SunlitSample out;
  out.L = T_cam.T * mp.sigma_s * p * T_sun.T * path.sun_radiance * (T_clouds / (pdf_t * pdf_light));
  out.r = pdf_t_all * (1.0 / pdf_t) * T_cam.r_l * T_sun.r_l;
  return out;
}

SampledSpectrum VolumePathIntegrator::transmittance(const Ray& ray, double t_end, const SampledWavelengths& lambda,
                                                    Sampler& sampler, PathCounters* counters) const {
  SampledSpectrum T = tracked_transmittance(ray, t_end, scene_.medium().path_coefficients(lambda), sampler, counters).T;
  if (scene_.clouds()) T *= scene_.clouds()->transmittance(ray, 0.0, t_end, sampler, &counters->collisions);
  return T;
}

TrackedTransmittance VolumePathIntegrator::tracked_transmittance(const Ray& ray, double t_end,
                                                                 const PathCoefficients& path, Sampler& sampler,
                                                                 PathCounters* counters) const {
  const AtmosphereMedium& medium = scene_.medium();
  const RadialRay radial = radial_ray(ray);
  const SphereHit top = intersect_sphere(radial, scene_.atmosphere().top_radius_m());
  if (!top.hit || top.t_far <= 0.0) return {};
  const double t0 = std::max(0.0, top.t_near), t1 = std::min(t_end, top.t_far);
  if (t1 <= t0) return {};
  if (options_.residual_ratio_tracking)
    return residual_ratio_tracking(medium, ray, radial, t0, t1, path, sampler, &counters->collisions, false);
  // Ratio tracking: T *= sigma_n / sigma_maj (hero), times the other
  // wavelengths' majorant-transmittance ratios; r_l the pattern's pdf had
  // each wavelength been the hero, over the hero's.
  MediumPoint mp;
  TrackedTransmittance out;
  const SampledSpectrum T_maj = sample_t_maj(
      medium, medium.coarse_shells(), ray, t0, t1, path, sampler, mp,
      [&](double, const glm::dvec3&, const SampledSpectrum& sigma_maj, const SampledSpectrum& T_maj_seg) {
        ++counters->collisions;
        const SampledSpectrum sigma_n = sigma_maj - mp.sigma_a - mp.sigma_s;
        const double pdf = T_maj_seg[0] * sigma_maj[0];
        out.T *= T_maj_seg * sigma_n * (1.0 / pdf);
        out.r_l *= T_maj_seg * sigma_maj * (1.0 / pdf);
        return true;
      });
  out.T *= T_maj * (1.0 / T_maj[0]);
  out.r_l *= T_maj * (1.0 / T_maj[0]);
  out.r_u = out.T;
  return out;
}

}  // namespace skyfarm

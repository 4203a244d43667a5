#include "common/lut/cloud_march.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "common/geometry/sphere_intersection.h"
#include "common/lut/invalid_argument.h"

namespace skyfarm {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A step's optical thickness against its piece's majorant: 0.5 keeps the
// midpoint rule's error in exp(-sigma dt) per step below ~1 % where the
// majorant is tight, and the budget caps the count where it is not.
constexpr double kOpticalStep = 0.5;
// The longest step inside a piece (m): a loose majorant over a long piece
// still gets samples every 250 m, the scale of a small cumulus.
constexpr double kMaxStep_m = 250.0;
// Per-bin temporaries on the stack (LutSky's own limit).
constexpr int kMaxBins = 512;
constexpr int kMaxOctaves = 16;

// The diffuse radiance of a conservative slab in the Eddington
// approximation, I(tau, mu) = I0(tau) + mu I1(tau) (mu > 0 upwards, tau
// from the top), lit at the top by a beam of irradiance F0 (normal to it) at
// cosine mu0, black below, no diffuse light entering at the top; g, tau
// already delta-scaled.  The moments of the transfer equation with p = 1 +
// 3 g mu mu' (omega = 1, k = 3 F0 / (4 pi), e(tau) = exp(-tau / mu0)):
//   dI1/dtau = -k e,            I1 = C1 + k mu0 e
//   dI0/dtau = (1 - g) I1 + k g mu0 e,   I0 = C2 + (1 - g) C1 tau - k mu0^2 e
// with Marshak's conditions I0 - 2/3 I1 = 0 at tau = 0 and I0 + 2/3 I1 = 0
// at tau = tau_total:
//   C1 = -k [mu0^2 (1 - e_T) + 2/3 mu0 (1 + e_T)] / (4/3 + (1 - g) tau_total)
//   C2 = 2/3 C1 + k mu0^2 + 2/3 k mu0.
// (Checks: tau_total -> 0 gives I = 0; a deep slab reflects F0 mu0 at the
// top: the upward flux 4 pi / 3 I1(0) -> F0 mu0.)  Per unit F0.
struct TwoStream {
  double I0 = 0.0, I1 = 0.0;
};
TwoStream two_stream_diffuse(double tau, double tau_total, double mu0, double g) {
  constexpr double kPiLocal = 3.14159265358979323846;
  const double k = 3.0 / (4.0 * kPiLocal);
  const double e = std::exp(-tau / mu0), e_T = std::exp(-tau_total / mu0);
  const double C1 = -k * (mu0 * mu0 * (1.0 - e_T) + 2.0 / 3.0 * mu0 * (1.0 + e_T)) / (4.0 / 3.0 + (1.0 - g) * tau_total);
  const double C2 = 2.0 / 3.0 * C1 + k * mu0 * mu0 + 2.0 / 3.0 * k * mu0;
  return {std::max(0.0, C2 + (1.0 - g) * C1 * tau - k * mu0 * mu0 * e), C1 + k * mu0 * e};
}

struct Piece {
  double t0, t1, sigma_maj;
  const CloudField* field;
};

}  // namespace

CloudMarch::CloudMarch(const LutSky& sky, const SceneClouds& clouds, CloudMarchOptions options)
    : sky_(sky), clouds_(clouds), options_(options), R_(sky.planet_radius_m()) {
  if (options_.max_steps < 1 || options_.sun_steps < 0 || options_.octaves < 1 || options_.octaves > kMaxOctaves ||
      options_.ambient_directions < 1)
    throw lut::invalid_argument("cloud march: bad options (max_steps ", options_.max_steps, ", sun_steps ",
                                options_.sun_steps, ", octaves ", options_.octaves, ")");
  const int B = sky.grid().size();
  phi_down_.assign(static_cast<std::size_t>(B), 0.0);
  phi_up_.assign(static_cast<std::size_t>(B), 0.0);
  if (!options_.ambient || clouds.fields().empty()) return;
  // Phi = int_hemisphere L dw = 2 pi <L> over directions uniform in solid
  // angle: rings at the midpoints of |mu| in [0, 1] (uniform in mu is uniform
  // in solid angle) times equally spaced azimuths.
  const int n = options_.ambient_directions;
  const int rings = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(n)))));
  const int azimuths = std::max(1, n / rings);
  std::vector<double> L(static_cast<std::size_t>(B));
  const auto hemisphere = [&](double altitude_m, double sign, std::vector<double>& phi) {
    const glm::dvec3 origin{0.0, 0.0, R_ + altitude_m};
    for (int i = 0; i < rings; ++i) {
      const double mu = sign * (i + 0.5) / rings, s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
      for (int j = 0; j < azimuths; ++j) {
        const double phi_az = 2.0 * kPi * (j + 0.5) / azimuths;
        sky.raymarch_radiance(origin, {s * std::cos(phi_az), s * std::sin(phi_az), mu}, L, false, 24);
        for (int b = 0; b < B; ++b) phi[static_cast<std::size_t>(b)] += L[static_cast<std::size_t>(b)];
      }
    }
    for (double& v : phi) v *= 2.0 * kPi / (rings * azimuths);
  };
  hemisphere(clouds.top_altitude_m(), 1.0, phi_down_);
  hemisphere(clouds.bottom_altitude_m(), -1.0, phi_up_);
}

// tau towards the sun from p: sun_steps steps doubling in length over the
// distance to the clouds' top shell (the whole layer's chord along the sun
// direction), each sampled at its midpoint in every field.
double CloudMarch::sun_optical_depth(const glm::dvec3& p) const {
  const int n = options_.sun_steps;
  if (n == 0) return 0.0;
  const Ray to_sun{p, sky_.sun().direction()};
  const double length = distance_to_sphere(to_sun, R_ + clouds_.top_altitude_m());
  if (!(length > 0.0)) return 0.0;
  double dt = length / (std::ldexp(1.0, n) - 1.0), t = 0.0, tau = 0.0;
  for (int k = 0; k < n; ++k, dt *= 2.0) {
    const glm::dvec3 q = to_sun.at(t + 0.5 * dt);
    double sigma = 0.0;
    for (const auto& field : clouds_.fields()) sigma += field->sigma_t(q);
    tau += sigma * dt;
    t += dt;
  }
  return tau;
}

// tau straight down from p (radius r) to the clouds' bottom, sun_steps
// steps doubling in length (at least one).
double CloudMarch::down_optical_depth(const glm::dvec3& p, double r) const {
  const double length = r - (R_ + clouds_.bottom_altitude_m());
  if (!(length > 0.0)) return 0.0;
  const int n = std::max(1, options_.sun_steps);
  const glm::dvec3 down = -p / r;
  double dt = length / (std::ldexp(1.0, n) - 1.0), t = 0.0, tau = 0.0;
  for (int k = 0; k < n; ++k, dt *= 2.0) {
    const glm::dvec3 q = p + (t + 0.5 * dt) * down;
    double sigma = 0.0;
    for (const auto& field : clouds_.fields()) sigma += field->sigma_t(q);
    tau += sigma * dt;
    t += dt;
  }
  return tau;
}

CloudMarch::Result CloudMarch::march(const Ray& ray, double t_max, std::span<double> L_cloud,
                                     std::span<double> T_cloud) const {
  const int B = sky_.grid().size();
  if (L_cloud.size() < static_cast<std::size_t>(B) || T_cloud.size() < static_cast<std::size_t>(B))
    throw lut::invalid_argument("cloud march: needs ", B, " values per output");
  std::fill(L_cloud.begin(), L_cloud.begin() + B, 0.0);
  Result result;
  // The pieces of every field, in increasing t (fields rarely overlap: where
  // they do, each piece is marched whole in the order of its start).
  std::vector<Piece> pieces;
  for (const auto& field : clouds_.fields())
    field->for_each_majorant(ray, 0.0, t_max, [&](double t0, double t1, double sigma_maj) {
      if (sigma_maj > 0.0 && t1 > t0) pieces.push_back({t0, t1, sigma_maj, field.get()});
      return true;
    });
  std::sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.t0 < b.t0; });

  const glm::dvec3 s = sky_.sun().direction();
  // Scattering angle between the sun's light (propagating along -s) and the
  // light towards the camera (along -d): cos = s . d, the same at every step.
  const double cos_theta = std::clamp(glm::dot(s, ray.d), -1.0, 1.0);
  const std::span<const double> E = sky_.sun_irradiance();
  std::array<double, kMaxBins> T_air;
  const double h_bottom = clouds_.bottom_altitude_m(), h_top = clouds_.top_altitude_m();
  const double h_range = std::max(h_top - h_bottom, 1e-9);

  double T = 1.0, weight_sum = 0.0, depth_sum = 0.0;
  int budget = options_.max_steps;
  const CloudField* phase_field = nullptr;
  std::array<double, kMaxOctaves> octave_weight{};  // a^i p_i(cos theta), per field's phase
  const bool two_stream = options_.multiple_scattering == CloudMultipleScattering::kTwoStream;
  const int octaves = two_stream ? 1 : options_.octaves;
  double g = 0.0;  // the field's asymmetry parameter
  for (std::size_t k = 0; k < pieces.size() && T >= options_.min_transmittance; ++k) {
    const Piece& piece = pieces[k];
    const CloudOptics& optics = piece.field->optics();
    if (piece.field != phase_field) {
      phase_field = piece.field;
      const double p = optics.phase.eval(cos_theta);
      g = std::clamp(optics.phase.mean_cosine(), -0.99, 0.99);
      double a = 1.0, c = 1.0;
      for (int i = 0; i < options_.octaves; ++i, a *= options_.octave_a, c *= options_.octave_c)
        octave_weight[static_cast<std::size_t>(i)] = a * (c * p + (1.0 - c) / (4.0 * kPi));
    }
    const double len = piece.t1 - piece.t0;
    const int pieces_left = static_cast<int>(pieces.size() - k - 1);
    const double wanted = std::ceil(std::max(piece.sigma_maj * len / kOpticalStep, len / kMaxStep_m));
    const int n = std::max(1, std::min(static_cast<int>(std::min(wanted, 1e6)), budget - pieces_left));
    budget -= n;
    const double dt = len / n;
    for (int i = 0; i < n && T >= options_.min_transmittance; ++i) {
      const double t = piece.t0 + (i + 0.5) * dt;
      const glm::dvec3 p = ray.at(t);
      const double sigma_t = piece.field->sigma_t(p);
      ++result.steps;
      if (!(sigma_t > 0.0)) continue;
      const double opacity = -std::expm1(-sigma_t * dt);  // 1 - exp(-sigma_t dt)
      const double r = glm::length(p);
      const glm::dvec3 up = p / r;
      // Sun: the octaves' phase and cloud transmittance (grey), then the
      // air's transmittance and E_sun per bin.
      const double tau_sun = sun_optical_depth(p);
      double sun = 0.0, b_pow = 1.0;
      if (!two_stream) {
        for (int i = 0; i < octaves; ++i, b_pow *= options_.octave_b)
          sun += octave_weight[static_cast<std::size_t>(i)] * std::exp(-b_pow * tau_sun);
      } else {
        // Delta-Eddington (f = g^2): the beam keeps the forward peak's light,
        // exp(-(1 - f) tau_sun), and scatters the rest with the phase function
        // (its peak capped at the Eddington phase's largest value, so the
        // peak's light is not counted twice); the diffuse field I0 + mu I1
        // of the scaled slab is seen through the true phase function as
        // f I(mu_v) + (1 - f)(I0 + g' mu_v I1) = I0 + g mu_v I1.
        const double mu0 = std::max(glm::dot(up, s), 0.02), scale = 1.0 - g * g, g_scaled = g / (1.0 + g);
        const double tau_above = scale * mu0 * tau_sun, tau_total = tau_above + scale * down_optical_depth(p, r);
        const double p_beam = std::min(octave_weight[0], (1.0 + 3.0 * g_scaled) / (4.0 * kPi));
        const TwoStream diffuse = two_stream_diffuse(tau_above, tau_total, mu0, g_scaled);
        sun = p_beam * std::exp(-scale * tau_sun) + std::max(0.0, diffuse.I0 + g * glm::dot(-ray.d, up) * diffuse.I1);
      }
      const double weight = T * optics.albedo * opacity;
      if (sun > 0.0) {
        sky_.transmittance_to_top(r, glm::dot(up, s), std::span<double>(T_air.data(), static_cast<std::size_t>(B)));
        for (int b = 0; b < B; ++b)
          L_cloud[static_cast<std::size_t>(b)] +=
              weight * sun * E[static_cast<std::size_t>(b)] * T_air[static_cast<std::size_t>(b)];
      }
      if (options_.ambient) {
        const double f = std::clamp((r - R_ - h_bottom) / h_range, 0.0, 1.0);
        for (int b = 0; b < B; ++b)
          L_cloud[static_cast<std::size_t>(b)] +=
              weight * (f * phi_down_[static_cast<std::size_t>(b)] + (1.0 - f) * phi_up_[static_cast<std::size_t>(b)]) /
              (4.0 * kPi);
      }
      weight_sum += T * opacity;
      depth_sum += T * opacity * t;
      T *= 1.0 - opacity;
    }
  }
  if (T < options_.min_transmittance) T = 0.0;  // what lies beyond adds < min_transmittance
  std::fill(T_cloud.begin(), T_cloud.begin() + B, T);
  result.transmittance = T;
  if (weight_sum > 0.0) result.mean_depth_m = depth_sum / weight_sum;
  return result;
}

void CloudMarch::composite(const glm::dvec3& view_dir, std::span<double> L) const {
  const int B = sky_.grid().size();
  const glm::dvec3 d = glm::normalize(view_dir);
  const Ray ray{{0.0, 0.0, R_ + sky_.observer_altitude_m()}, d};
  const double t_ground = ground_distance(ray, R_);
  const double t_max = t_ground >= 0.0 ? t_ground : std::numeric_limits<double>::infinity();
  std::array<double, kMaxBins> L_cloud, T_cloud, L_air, T_air;
  const std::span<double> Lc(L_cloud.data(), static_cast<std::size_t>(B)),
      Tc(T_cloud.data(), static_cast<std::size_t>(B)), La(L_air.data(), static_cast<std::size_t>(B)),
      Ta(T_air.data(), static_cast<std::size_t>(B));
  const Result r = march(ray, t_max, Lc, Tc);
  if (r.mean_depth_m < 0.0) return;  // no cloud on this ray: the sky as it was
  sky_.aerial_perspective(d, r.mean_depth_m, La, Ta);
  const double T = r.transmittance;
  for (int b = 0; b < B; ++b) {
    const std::size_t i = static_cast<std::size_t>(b);
    const double v = T * L[i] + (1.0 - T) * L_air[i] + T_air[i] * L_cloud[i];
    L[i] = std::isfinite(v) && v >= 0.0 ? v : 0.0;
  }
}

}  // namespace skyfarm

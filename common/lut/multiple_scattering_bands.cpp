#include "common/lut/multiple_scattering_bands.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/core/constants.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/mirrored_rings.h"
#include "common/lut/segment_integral.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

namespace {

constexpr int kMomentNodes = 4096;
constexpr double kMaxFms = 1.0 - 1e-3;  // as multiple_scattering_lut.cpp

// mu_s of node x in [-1, 1] (header: denser near the horizon) and back.
double warped_mu_s(double x) { return x * (0.3 + 0.7 * std::abs(x)); }
double unwarped_mu_s(double mu_s) {
  const double a = std::min(1.0, std::abs(mu_s));
  return std::copysign((std::sqrt(0.09 + 2.8 * a) - 0.3) / 1.4, mu_s);
}

// One direction's march from radius r: per step the per-scatterer weights
// T(x, x_k-) int_k exp(-sigma_t s) ds sigma_s,c ([k][c][b], single
// precision as the tables), the step's transmittance-table radius and the
// sun's zenith cosine at the step as a sin_s + b mu_s; and, when the ray
// ends on the ground, T(x, x_g) and the same for the ground point.
struct DirectionMarch {
  std::vector<float> weights;
  std::vector<TransmittanceLut::RadiusCoord> radius;
  std::vector<double> a, b, T_ground;
  double a_ground = 0.0, b_ground = 0.0;
  bool hits_ground = false;

  void run(const MediumTable& medium, const TransmittanceLut& transmittance, double r, double mu,
           double sin_theta_cos_phi, int steps) {
    const std::size_t B = static_cast<std::size_t>(medium.bins()), C = static_cast<std::size_t>(medium.scatterers());
    const std::size_t S = static_cast<std::size_t>(steps);
    const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
    hits_ground = lut::ray_hits_ground(r, mu, R);
    const double t_end = hits_ground ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top);
    std::vector<double> t_mid(S), dt(S), s_t(B), s_c(C * B), T(B, 1.0);
    lut::place_steps(r, mu, t_end, steps, t_mid.data(), dt.data());
    weights.assign(S * C * B, 0.0f);
    radius.resize(S);
    a.resize(S);
    b.resize(S);
    for (std::size_t k = 0; k < S; ++k) {
      const double rk = std::max(R, lut::radius_at(r, mu, t_mid[k]));
      const MediumTable::Node node = medium.locate(rk - R);
      medium.sigma_t(node, s_t.data());
      medium.sigma_s_per_scatterer(node, s_c.data());
      for (std::size_t bin = 0; bin < B; ++bin) {
        double integral;
        const double T_seg = lut::T_and_in_scattering_integral(s_t[bin], dt[k], &integral);
        for (std::size_t c = 0; c < C; ++c)
          weights[(k * C + c) * B + bin] = static_cast<float>(T[bin] * integral * s_c[c * B + bin]);
        T[bin] *= T_seg;
      }
      radius[k] = transmittance.locate_r(rk);
      a[k] = t_mid[k] * sin_theta_cos_phi / rk;
      b[k] = (r + t_mid[k] * mu) / rk;
    }
    T_ground = T;
    a_ground = t_end * sin_theta_cos_phi / R;
    b_ground = (r + t_end * mu) / R;
  }

  // F[c * B + b] = sum_k weights T_sun(x_k) for the sun (sin_s, 0, mu_s).
  void sunlit(const TransmittanceLut& transmittance, std::size_t B, std::size_t C, double sin_s, double mu_s,
              double* T_sun, double* F) const {
    std::fill(F, F + C * B, 0.0);
    for (std::size_t k = 0; k < radius.size(); ++k) {
      const double mu_k = std::clamp(a[k] * sin_s + b[k] * mu_s, -1.0, 1.0);
      const double u = transmittance.mu_position(radius[k], mu_k);
      if (u < 0.0) continue;  // the planet hides the sun
      transmittance.lookup(radius[k], u, T_sun);
      const float* w = weights.data() + k * C * B;
      for (std::size_t c = 0; c < C; ++c)
        for (std::size_t bin = 0; bin < B; ++bin) F[c * B + bin] += w[c * B + bin] * T_sun[bin];
    }
  }
};

}  // namespace

// P_l by the three-term recurrence, l P_l = (2l - 1) mu P_{l-1} - (l - 1) P_{l-2}.
std::vector<double> phase_moments(const MediumTable& medium, int max_band) {
  const std::size_t B = static_cast<std::size_t>(medium.bins()), C = static_cast<std::size_t>(medium.scatterers());
  const std::size_t L = static_cast<std::size_t>(std::max(0, max_band));
  std::vector<double> g((L + 1) * C * B, 0.0), p(C * B), P(L + 1);
  for (int i = 0; i < kMomentNodes; ++i) {
    const double x = (i + 0.5) / kMomentNodes, theta = kPi * x * x, d_theta = 2.0 * kPi * x / kMomentNodes;
    const double mu = std::cos(theta), weight = 2.0 * kPi * std::sin(theta) * d_theta;
    medium.phase_exact(mu, p.data());
    P[0] = 1.0;
    if (L >= 1) P[1] = mu;
    for (std::size_t l = 2; l <= L; ++l) P[l] = ((2.0 * l - 1.0) * mu * P[l - 1] - (l - 1.0) * P[l - 2]) / l;
    for (std::size_t l = 0; l <= L; ++l)
      for (std::size_t j = 0; j < C * B; ++j) g[l * C * B + j] += weight * P[l] * p[j];
  }
  return g;
}

MultipleScatteringBands MultipleScatteringBands::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                                       const GroundIrradianceLut& ground, int max_band,
                                                       int mu_s_samples, int altitude_samples, int rings, int azimuths,
                                                       int steps) {
  if (max_band < 0 || max_band > lut::kMaxHarmonicBand || mu_s_samples < 2 || altitude_samples < 2 || rings < 2 ||
      azimuths < 1 || steps < 1)
    throw lut::invalid_argument("multiple-scattering bands: bad resolution: band ", max_band, ", ", mu_s_samples, "x",
                                altitude_samples, " nodes, ", rings, "x", azimuths, " directions, ", steps, " steps");
  MultipleScatteringBands t;
  t.max_band_ = max_band;
  t.harmonics_ = max_band > 0 ? lut::mirror_harmonic_count(max_band) : 0;
  t.bins_ = medium.bins();
  t.scatterers_ = medium.scatterers();
  t.n_mu_s_ = mu_s_samples;
  t.n_h_ = altitude_samples;
  t.top_altitude_ = medium.top_altitude_m();
  if (max_band == 0) return t;
  t.moments_ = phase_moments(medium, max_band);
  const std::size_t B = static_cast<std::size_t>(t.bins_), C = static_cast<std::size_t>(t.scatterers_);
  const std::size_t K = static_cast<std::size_t>(t.harmonics_), M = static_cast<std::size_t>(mu_s_samples);
  const std::size_t D = static_cast<std::size_t>(rings * azimuths);
  const int all_harmonics = t.harmonics_;
  t.values_.assign(static_cast<std::size_t>(altitude_samples) * M * K * B, 0.0f);
  const double R = medium.planet_radius_m();
  const std::vector<double>& albedo = medium.ground_albedo();
  const TransmittanceLut::RadiusCoord ground_rc = transmittance.locate_r(R);

  std::vector<DirectionMarch> marches(D);
  DirectionMarch towards_sun;
  std::vector<double> Y(D * static_cast<std::size_t>(all_harmonics)), solid_angle(D), sin_cos(D), mu_dir(D);
  std::vector<double> T_sun(B), F(C * B), A(C * B), phase(C * B), L1(B), irradiance(B), acc(K * B), iso(B), f_ms(B);
  std::array<double, lut::mirror_harmonic_count(lut::kMaxHarmonicBand)> Y_sun;
  for (int j = 0; j < altitude_samples; ++j) {
    const double x_h = static_cast<double>(j) / (altitude_samples - 1);
    const double r = R + t.top_altitude_ * x_h * x_h;
    const lut::Rings ring_set = lut::mirrored_rings(rings, lut::horizon_mu(r, R));
    for (int i = 0; i < rings; ++i) {
      const double mu = ring_set.mu[static_cast<std::size_t>(i)];
      const double sin_theta = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
      for (int az = 0; az < azimuths; ++az) {
        const std::size_t d = static_cast<std::size_t>(i * azimuths + az);
        const double phi = kPi * (az + 0.5) / azimuths;
        const double x = sin_theta * std::cos(phi), y = sin_theta * std::sin(phi);
        // Each direction stands for itself and its mirror image (-y).
        solid_angle[d] = 4.0 * kPi * ring_set.weight[static_cast<std::size_t>(i)] / azimuths;
        sin_cos[d] = x;
        mu_dir[d] = mu;
        lut::mirror_harmonics(max_band, mu, x, y * y, Y.data() + d * static_cast<std::size_t>(all_harmonics));
        marches[d].run(medium, transmittance, r, mu, x, steps);
      }
    }
    // Hillaire's f_ms on the same directions: the fraction of the light
    // scattered isotropically at x that the air around scatters again.
    std::fill(f_ms.begin(), f_ms.end(), 0.0);
    for (std::size_t d = 0; d < D; ++d)
      for (std::size_t k = 0; k < static_cast<std::size_t>(steps); ++k)
        for (std::size_t c = 0; c < C; ++c)
          for (std::size_t b = 0; b < B; ++b)
            f_ms[b] += solid_angle[d] * kInv4Pi * marches[d].weights[(k * C + c) * B + b];
    for (double& f : f_ms) f = std::min(f, kMaxFms);
    for (std::size_t col = 0; col < M; ++col) {
      const double mu_s = warped_mu_s(-1.0 + 2.0 * static_cast<double>(col) / static_cast<double>(M - 1));
      const double sin_s = std::sqrt(std::max(0.0, (1.0 - mu_s) * (1.0 + mu_s)));
      // The control variate: F_c towards the sun itself.
      towards_sun.run(medium, transmittance, r, mu_s, sin_s, steps);
      towards_sun.sunlit(transmittance, B, C, sin_s, mu_s, T_sun.data(), A.data());
      std::fill(acc.begin(), acc.end(), 0.0);
      std::fill(iso.begin(), iso.end(), 0.0);
      for (std::size_t d = 0; d < D; ++d) {
        const DirectionMarch& m = marches[d];
        const double nu = std::clamp(sin_cos[d] * sin_s + mu_dir[d] * mu_s, -1.0, 1.0);
        medium.phase(nu, phase.data());
        m.sunlit(transmittance, B, C, sin_s, mu_s, T_sun.data(), F.data());
        for (std::size_t b = 0; b < B; ++b) {
          double v = 0.0, u = 0.0;
          for (std::size_t c = 0; c < C; ++c) {
            v += phase[c * B + b] * (F[c * B + b] - A[c * B + b]);
            u += F[c * B + b];
          }
          L1[b] = v;
          iso[b] += solid_angle[d] * kInv4Pi * kInv4Pi * u;
        }
        if (m.hits_ground) {
          // The ground's Lambertian light: the sun and the sky on it.
          const double mu_g = std::clamp(m.a_ground * sin_s + m.b_ground * mu_s, -1.0, 1.0);
          std::fill(irradiance.begin(), irradiance.end(), 0.0);
          if (mu_g > 0.0) {
            transmittance.lookup(ground_rc, transmittance.mu_position(ground_rc, mu_g), irradiance.data());
            for (std::size_t b = 0; b < B; ++b) {
              irradiance[b] *= mu_g;
              iso[b] += solid_angle[d] * kInv4Pi * m.T_ground[b] * albedo[b] * kInvPi * irradiance[b];
            }
          }
          ground.lookup_add(mu_g, irradiance.data());
          for (std::size_t b = 0; b < B; ++b) L1[b] += m.T_ground[b] * albedo[b] * kInvPi * irradiance[b];
        }
        const double* Yd = Y.data() + d * static_cast<std::size_t>(all_harmonics);
        for (std::size_t k = 0; k < K; ++k) {
          const double w = solid_angle[d] * Yd[k];
          for (std::size_t b = 0; b < B; ++b) acc[k * B + b] += w * L1[b];
        }
      }
      // The exact part of the control variate: A_c g_l,c Y_lm(s).
      lut::mirror_harmonics(max_band, mu_s, sin_s, 0.0, Y_sun.data());
      for (int l = 0; l <= max_band; ++l)
        for (int mm = 0; mm <= l; ++mm) {
          const std::size_t k = static_cast<std::size_t>(lut::mirror_harmonic_index(l, mm));
          for (std::size_t c = 0; c < C; ++c)
            for (std::size_t b = 0; b < B; ++b)
              acc[k * B + b] += A[c * B + b] * t.moment(l, static_cast<int>(c), static_cast<int>(b)) * Y_sun[k];
        }
      // Band 0: what the true first-order light adds to the mean that
      // Hillaire's table already carries (isotropic phase, the direct sun
      // on the ground), carried through the higher orders as his is.
      for (std::size_t b = 0; b < B; ++b)
        acc[b] = (acc[b] - std::sqrt(4.0 * kPi) * iso[b]) / (1.0 - f_ms[b]);
      float* out = t.values_.data() + (static_cast<std::size_t>(j) * M + col) * K * B;
      for (std::size_t n = 0; n < K * B; ++n) out[n] = static_cast<float>(acc[n]);
    }
  }
  return t;
}

double MultipleScatteringBands::mu_s_position(double mu_s) const {
  return 0.5 * (unwarped_mu_s(std::clamp(mu_s, -1.0, 1.0)) + 1.0) * (n_mu_s_ - 1);
}

void MultipleScatteringBands::coefficients(double altitude_m, double mu_s, float* out) const {
  const std::size_t KB = static_cast<std::size_t>(harmonics_ * bins_);
  if (KB == 0) return;
  const double v = std::sqrt(std::clamp(altitude_m / top_altitude_, 0.0, 1.0)) * (n_h_ - 1);
  const std::size_t j = std::min(static_cast<std::size_t>(v), static_cast<std::size_t>(n_h_ - 2));
  const double u = mu_s_position(mu_s);
  const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_mu_s_ - 2));
  const float fj = static_cast<float>(v - static_cast<double>(j)), fi = static_cast<float>(u - static_cast<double>(i));
  const std::size_t row = static_cast<std::size_t>(n_mu_s_) * KB;
  const float* v00 = values_.data() + j * row + i * KB;
  const float *v01 = v00 + KB, *v10 = v00 + row, *v11 = v10 + KB;
  const float w00 = (1.0f - fj) * (1.0f - fi), w01 = (1.0f - fj) * fi, w10 = fj * (1.0f - fi), w11 = fj * fi;
  for (std::size_t n = 0; n < KB; ++n) out[n] = w00 * v00[n] + w01 * v01[n] + w10 * v10[n] + w11 * v11[n];
}

void MultipleScatteringBands::add_source(const float* coefficients, double mu_v, double x_v, const float* w_c,
                                         double* acc) const {
  if (max_band_ == 0) return;
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  std::array<double, lut::mirror_harmonic_count(lut::kMaxHarmonicBand)> Y;
  lut::mirror_harmonics(max_band_, mu_v, x_v, std::max(0.0, 1.0 - mu_v * mu_v - x_v * x_v), Y.data());
  std::array<double, 512> band;  // one band's sum over m, per bin
  for (int l = 0; l <= max_band_; ++l) {
    std::fill(band.begin(), band.begin() + static_cast<std::ptrdiff_t>(B), 0.0);
    for (int m = 0; m <= l; ++m) {
      const int k = lut::mirror_harmonic_index(l, m);
      const float* a = coefficients + static_cast<std::size_t>(k) * B;
      for (std::size_t b = 0; b < B; ++b) band[b] += a[b] * Y[static_cast<std::size_t>(k)];
    }
    const double* g = moments_.data() + static_cast<std::size_t>(l) * C * B;
    for (std::size_t c = 0; c < C; ++c)
      for (std::size_t b = 0; b < B; ++b) acc[b] += w_c[c * B + b] * g[c * B + b] * band[b];
  }
}

}  // namespace skyfarm

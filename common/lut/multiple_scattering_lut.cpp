#include "common/lut/multiple_scattering_lut.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "common/core/constants.h"
#include "common/lut/bilinear.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/mirrored_rings.h"
#include "common/lut/segment_integral.h"
#include "common/lut/shell_geometry.h"
#include "common/lut/simd_clones.h"

namespace skyfarm {

namespace {
constexpr double kMaxFms = 1.0 - 1e-3;
constexpr std::size_t kDefaultBins = kDefaultLutBins;

// acc[b] += weight[b] (w00 v00 + w01 v01 + w10 v10 + w11 v11)[b]: a bilinear
// look-up with its weights given (lut::BilinearF::weighted_add).
template <class Size>
[[gnu::always_inline]] inline void weighted_add4(Size B, const float* v00, const float* v01, const float* v10,
                                                 const float* v11, float w00, float w01, float w10, float w11,
                                                 const float* weight, float* __restrict acc) {
  for (std::size_t b = 0; b < B; ++b)
    acc[b] += weight[b] * (w00 * v00[b] + w01 * v01[b] + w10 * v10[b] + w11 * v11[b]);
}

}  // namespace

SKYFARM_LUT_SIMD_CLONES
MultipleScatteringLut MultipleScatteringLut::build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                                   int mu_s_samples, int altitude_samples, int directions, int steps) {
  if (mu_s_samples < 2 || altitude_samples < 2 || directions < 1 || steps < 1)
    throw lut::invalid_argument("multiple-scattering LUT: bad resolution ", mu_s_samples, "x", altitude_samples, ", ",
                                directions, " directions, ", steps, " steps");
  MultipleScatteringLut m;
  m.bins_ = medium.bins();
  m.n_mu_s_ = mu_s_samples;
  m.n_h_ = altitude_samples;
  m.top_altitude_ = medium.top_altitude_m();
  const std::size_t B = static_cast<std::size_t>(m.bins_), S = static_cast<std::size_t>(steps);
  const int ring_count = std::max(2, directions / 2);
  const std::size_t N = static_cast<std::size_t>(ring_count);
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  m.values_.assign(static_cast<std::size_t>(altitude_samples * mu_s_samples) * B, 0.0f);
  const std::vector<double>& albedo = medium.ground_albedo();
  const TransmittanceLut::RadiusCoord ground_rc = transmittance.locate_r(R);

  // Per altitude row and ring, everything that does not depend on the sun:
  // the weights w_ring T(x, x_t) int_seg exp(-sigma_t s) ds sigma_s(x_t) of
  // every step (the ring's mirror pair together), the step's T-LUT radius,
  // and mu_s at the step as a sin_s + b mu_s.  (W and the sums over the
  // samples in single precision, as the tables: bilinear.h.)
  std::vector<float> W(N * S * B);
  std::vector<double> T_ground(N * B), f_ms(B), s_t(B), s_s(B), L(B), T_sun(B);
  std::vector<float> T_acc(B);
  std::vector<TransmittanceLut::RadiusCoord> rc(N * S);
  std::vector<double> a(N * S), bcoef(N * S), a_g(N), b_g(N), w_dir(N), t_mid(S), dt(S);
  std::vector<char> hits(N);
  std::vector<double> r_step(S);
  std::vector<MediumTable::Node> medium_node(S);
  const std::size_t M = static_cast<std::size_t>(mu_s_samples);
  std::vector<double> mu_s(M), sin_s(M), u_T(M);
  std::vector<float> L_all(M * B), w00(M), w01(M), w10(M), w11(M);
  std::vector<int> node(M);
  for (std::size_t col = 0; col < M; ++col) {
    mu_s[col] = -1.0 + 2.0 * static_cast<double>(col) / static_cast<double>(M - 1);
    sin_s[col] = std::sqrt(std::max(0.0, 1.0 - mu_s[col] * mu_s[col]));
  }
  for (int j = 0; j < altitude_samples; ++j) {
    const double r = R + m.top_altitude_ * j / (altitude_samples - 1);
    std::fill(f_ms.begin(), f_ms.end(), 0.0);
    const lut::Rings rings = lut::mirrored_rings(ring_count, lut::horizon_mu(r, R));
    for (std::size_t i = 0; i < N; ++i) {
      const double mu = rings.mu[i], sin_theta = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
      w_dir[i] = rings.weight[i];
      hits[i] = lut::ray_hits_ground(r, mu, R);
      const double t_end = hits[i] ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R_top);
      lut::place_steps(r, mu, t_end, steps, t_mid.data(), dt.data());
      // (The steps' weights in single precision, as W is stored; f_ms sums
      // them in double.)
      std::fill(T_acc.begin(), T_acc.end(), 1.0f);
      const float w_ring = static_cast<float>(w_dir[i]);
      // The steps' coefficient rows are fetched ahead: in march order each
      // step's rows are new and the table (2 MB) is not in the L2 cache.
      for (std::size_t k = 0; k < S; ++k) {
        r_step[k] = lut::radius_at(r, mu, t_mid[k]);
        medium_node[k] = medium.locate(r_step[k] - R);
        medium.prefetch_sigma(medium_node[k]);
      }
      for (std::size_t k = 0; k < S; ++k) {
        const double rk = r_step[k];
        const MediumTable::Node node = medium_node[k];
        medium.sigma_t(node, s_t.data());
        medium.sigma_s(node, s_s.data());
        float* Wk = W.data() + (i * S + k) * B;
        const float dt_k = static_cast<float>(dt[k]);
        for (std::size_t b = 0; b < B; ++b) {
          float integral;
          const float T_seg = lut::T_and_in_scattering_integral_f(static_cast<float>(s_t[b]), dt_k, &integral);
          const float w = T_acc[b] * integral * static_cast<float>(s_s[b]) * w_ring;
          Wk[b] = w;
          f_ms[b] += w;
          T_acc[b] *= T_seg;
        }
        rc[i * S + k] = transmittance.locate_r(rk);
        // x_t = (0, 0, r) + t w, w = (sin_theta cos_phi, +-sin_theta sin_phi, mu),
        // s = (sin_s, 0, mu_s): x_t . s / r_t = a sin_s + b mu_s.
        a[i * S + k] = t_mid[k] * sin_theta * rings.cos_phi[i] / rk;
        bcoef[i * S + k] = (r + t_mid[k] * mu) / rk;
      }
      if (hits[i]) {
        for (std::size_t b = 0; b < B; ++b) T_ground[i * B + b] = T_acc[b] * w_dir[i];
        a_g[i] = t_end * sin_theta * rings.cos_phi[i] / R;
        b_g[i] = (r + t_end * mu) / R;
      }
    }
    for (std::size_t b = 0; b < B; ++b) {
      if (!(f_ms[b] <= kMaxFms)) {
        f_ms[b] = kMaxFms;
        ++m.clamped_;
      }
    }
    // Single scattering towards x from every sample, for every sun (column)
    // at once: the samples outside, so that the two transmittance rows of a
    // sample's radius stay in cache while all columns read them.
    // Every column's node and bilinear weights come from one vectorisable
    // pass per sample (TransmittanceLut::bilinear per look-up costs as much
    // as the look-up's sum at 32 bins).
    std::fill(L_all.begin(), L_all.end(), 0.0f);
    const std::size_t stride = transmittance.radius_stride();
    const int last_node = transmittance.mu_samples() - 2;
    for (std::size_t q = 0; q < N * S; ++q) {
      const float fj = static_cast<float>(rc[q].fj), gj = 1.0f - fj;
      const float* Wq = W.data() + q * B;
      for (std::size_t col = 0; col < M; ++col) {
        const double mu_q = std::min(1.0, std::max(-1.0, a[q] * sin_s[col] + bcoef[q] * mu_s[col]));
        u_T[col] = transmittance.mu_position(rc[q], mu_q);
        const int i = std::min(static_cast<int>(std::max(u_T[col], 0.0)), last_node);  // node_of
        const float f = static_cast<float>(u_T[col] - i);
        node[col] = i;
        w00[col] = gj * (1.0f - f);
        w01[col] = gj * f;
        w10[col] = fj * (1.0f - f);
        w11[col] = fj * f;
      }
      // (The bin count as a compile-time constant where it is the default:
      // each look-up's pass over 32 bins is two AVX-512 iterations, and
      // straight-line code without the loop's remainder handling.)
      const auto suns = [&](auto bins) __attribute__((always_inline)) {
        for (std::size_t col = 0; col < M; ++col)
          if (u_T[col] >= 0.0) {
            const float* v = transmittance.node_values(rc[q], static_cast<std::size_t>(node[col]));
            weighted_add4(bins, v, v + B, v + stride, v + stride + B, w00[col], w01[col], w10[col], w11[col], Wq,
                          L_all.data() + col * B);
          }
      };
      if (B == kDefaultBins)
        suns(std::integral_constant<std::size_t, kDefaultBins>{});
      else
        suns(B);
    }
    for (std::size_t col = 0; col < M; ++col) {
      std::copy(L_all.begin() + static_cast<std::ptrdiff_t>(col * B),
                L_all.begin() + static_cast<std::ptrdiff_t>((col + 1) * B), L.begin());
      for (std::size_t b = 0; b < B; ++b) L[b] *= kInv4Pi;  // the sun's phase p_u
      // The ground's Lambertian reflection of the attenuated sun (Hillaire's code,
      // IntegrateScatteredLuminance "bounced light off the earth").
      for (std::size_t i = 0; i < N; ++i) {
        if (!hits[i]) continue;
        const double mu_g = std::clamp(a_g[i] * sin_s[col] + b_g[i] * mu_s[col], -1.0, 1.0);
        if (mu_g <= 0.0) continue;
        transmittance.lookup(ground_rc, transmittance.mu_position(ground_rc, mu_g), T_sun.data());
        for (std::size_t b = 0; b < B; ++b) L[b] += T_ground[i * B + b] * T_sun[b] * mu_g * albedo[b] * kInvPi;
      }
      float* out = m.values_.data() + (static_cast<std::size_t>(j) * mu_s_samples + col) * B;
      for (std::size_t b = 0; b < B; ++b) out[b] = static_cast<float>(L[b] / (1.0 - f_ms[b]));
    }
  }
  return m;
}

MultipleScatteringLut::AltitudeCoord MultipleScatteringLut::locate_altitude(double altitude_m) const {
  const double u = std::clamp(altitude_m / top_altitude_, 0.0, 1.0) * (n_h_ - 1);
  const std::size_t j = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_h_ - 2));
  return {j * static_cast<std::size_t>(n_mu_s_) * static_cast<std::size_t>(bins_), u - static_cast<double>(j)};
}

void MultipleScatteringLut::lookup(const AltitudeCoord& a, double u, double* out) const {
  bilinear(a, u).eval(bins_, out);
}

void MultipleScatteringLut::lookup_weighted_add(const AltitudeCoord& a, double u, const double* weight,
                                                double* acc) const {
  bilinear(a, u).weighted_add(bins_, weight, acc);
}

}  // namespace skyfarm

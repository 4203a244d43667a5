#include "common/lut/scattering_march.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "common/core/constants.h"
#include "common/lut/ground_irradiance_lut.h"
#include "common/lut/multiple_scattering_bands.h"
#include "common/lut/segment_integral.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {

namespace {

// Views per tile in add_inscattering.
constexpr std::size_t kViewTile = 32;
// The bin count the per-view loops are specialised for.
constexpr std::size_t kDefaultBins = kDefaultLutBins;

// The sums over the steps are in single precision, like the tables they
// read (bilinear.h): a step's weights, the views' phase values and their
// partial sums are floats, added to the caller's doubles once per call.

// L[b] += (w0 p0 + c1 w1 p1)[b] T_sun[b] + w_ms[b] Psi[b], T_sun and Psi
// bilinear from their tables: the sky-view build's innermost loop, one pass
// over the bins.  (__restrict: L never overlaps the tables or weights;
// without it the loop needs more run-time alias checks than GCC emits, and
// stays scalar.)
inline void add_source(std::size_t B, float* __restrict L, const float* w0, const float* p0, const float* w1,
                       const float* p1, float c1, const lut::BilinearF& t, const float* w_ms,
                       const lut::BilinearF& m) {
  const float *t00 = t.v00, *t01 = t.v01, *t10 = t.v10, *t11 = t.v11;
  const float *m00 = m.v00, *m01 = m.v01, *m10 = m.v10, *m11 = m.v11;
  const float tw00 = static_cast<float>(t.w00), tw01 = static_cast<float>(t.w01), tw10 = static_cast<float>(t.w10),
              tw11 = static_cast<float>(t.w11);
  const float mw00 = static_cast<float>(m.w00), mw01 = static_cast<float>(m.w01), mw10 = static_cast<float>(m.w10),
              mw11 = static_cast<float>(m.w11);
  for (std::size_t b = 0; b < B; ++b) {
    const float T_sun = tw00 * t00[b] + tw01 * t01[b] + tw10 * t10[b] + tw11 * t11[b];
    const float psi = mw00 * m00[b] + mw01 * m01[b] + mw10 * m10[b] + mw11 * m11[b];
    L[b] += (w0[b] * p0[b] + c1 * (w1[b] * p1[b])) * T_sun + w_ms[b] * psi;
  }
}

// The same with T and Psi linear between two of the rows that radius_rows
// and altitude_rows built for the step: t, t + B and m, m + B.
template <class Size>
[[gnu::always_inline]] inline void add_source_rows(Size B, float* __restrict L, const float* w0, const float* p0,
                                                   const float* w1, const float* p1, float c1, const float* t,
                                                   float ft, const float* m, float fm, const float* w_ms) {
  const float gt = 1.0f - ft, gm = 1.0f - fm;
  for (std::size_t b = 0; b < B; ++b) {
    const float T_sun = gt * t[b] + ft * t[B + b];
    const float psi = gm * m[b] + fm * m[B + b];
    L[b] += (w0[b] * p0[b] + c1 * (w1[b] * p1[b])) * T_sun + w_ms[b] * psi;
  }
}

// L[b] += w[b] (row m and m + B, linear): the multiple scattering of a view
// whose point the planet hides from the sun.
template <class Size>
[[gnu::always_inline]] inline void add_weighted_row(Size B, float* __restrict L, const float* m, float f,
                                                    const float* w) {
  const float g = 1.0f - f;
  for (std::size_t b = 0; b < B; ++b) L[b] += w[b] * (g * m[b] + f * m[B + b]);
}

// One step through a segment, per bin: T1 = T0 T_seg and w = T0 int_seg
// exp(-sigma_t s) ds.  (Separate restrict-qualified arrays, so that the loop
// vectorises without run-time alias checks.)
inline void segment_weights(std::size_t B, const double* __restrict T0, const double* __restrict sigma_t, double dt,
                            double* __restrict T1, double* __restrict w) {
  for (std::size_t b = 0; b < B; ++b) {
    double integral;
    T1[b] = T0[b] * lut::T_and_in_scattering_integral(sigma_t[b], dt, &integral);
    w[b] = T0[b] * integral;
  }
}

inline void multiply(std::size_t B, const double* __restrict a, const double* __restrict b, float* __restrict out) {
  for (std::size_t k = 0; k < B; ++k) out[k] = static_cast<float>(a[k] * b[k]);
}

}  // namespace

ScatteringMarch::ScatteringMarch(const MediumTable& medium, const TransmittanceLut& transmittance,
                                 const MultipleScatteringLut* multiple_scattering,
                                 const GroundIrradianceLut* ground_irradiance)
    : medium_(medium),
      transmittance_(transmittance),
      ms_(multiple_scattering),
      gi_(ground_irradiance),
      bins_(medium.bins()),
      scatterers_(medium.scatterers()) {
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  s_t_.resize(B);
  s_s_.resize(B);
  s_c_.resize(C * B);
  w_phase_.resize(B);
  tmp_.resize(B);
  u_T_.resize(kViewTile);
  u_ms_.resize(kViewTile);
  node_T_.resize(kViewTile);
  node_ms_.resize(kViewTile);
  frac_T_.resize(kViewTile);
  frac_ms_.resize(kViewTile);
  L_f_.resize(kViewTile * B);
  // At most kViewTile rows in each (add_step builds rows only then).
  rows_T_.resize(kViewTile * B);
  rows_M_.resize(kViewTile * B);
}

void ScatteringMarch::prepare(double r0, double mu, double t_end, bool ends_on_ground, int steps) {
  steps_ = std::max(1, steps);
  t_mid_.resize(static_cast<std::size_t>(steps_));
  dt_.resize(static_cast<std::size_t>(steps_));
  lut::place_steps(r0, mu, t_end, steps_, t_mid_.data(), dt_.data());
  t_end_ = t_end;
  prepare_steps(r0, mu, ends_on_ground);
}

void ScatteringMarch::prepare_boundaries(double r0, double mu, std::span<const double> boundaries,
                                         bool ends_on_ground) {
  steps_ = std::max<int>(1, static_cast<int>(boundaries.size()) - 1);
  t_mid_.assign(static_cast<std::size_t>(steps_), 0.0);
  dt_.assign(static_cast<std::size_t>(steps_), 0.0);
  for (std::size_t k = 0; k + 1 < boundaries.size(); ++k) {
    t_mid_[k] = 0.5 * (boundaries[k] + boundaries[k + 1]);
    dt_[k] = boundaries[k + 1] - boundaries[k];
  }
  t_end_ = boundaries.empty() ? 0.0 : boundaries.back();
  prepare_steps(r0, mu, ends_on_ground);
}

// The sun-independent part: per step the coefficients at the midpoint, the
// segment's transmittance and in-scattering integral, and the weights.
SKYFARM_LUT_SIMD_CLONES
void ScatteringMarch::prepare_steps(double r0, double mu, bool ends_on_ground) {
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  const std::size_t S = static_cast<std::size_t>(steps_);
  const double R = medium_.planet_radius_m();
  r0_ = r0;
  mu_ = mu;
  ends_on_ground_ = ends_on_ground;
  w_c_.resize(S * C * B);
  w_ms_.resize(S * B);
  T_before_.resize((S + 1) * B);
  radius_.resize(S);
  ms_altitude_.resize(S);
  c_mu_.resize(S);
  c_nu_.resize(S);
  std::fill(T_before_.begin(), T_before_.begin() + static_cast<std::ptrdiff_t>(B), 1.0);
  for (std::size_t k = 0; k < S; ++k) {
    const double rk = std::max(R, lut::radius_at(r0, mu, t_mid_[k]));
    const double altitude = rk - R;
    radius_[k] = transmittance_.locate_r(rk);
    if (ms_) ms_altitude_[k] = ms_->locate_altitude(altitude);
    c_mu_[k] = r0 / rk;
    c_nu_[k] = t_mid_[k] / rk;
    const MediumTable::Node node = medium_.locate(altitude);
    medium_.sigma_t(node, s_t_.data());
    medium_.sigma_s(node, s_s_.data());
    medium_.sigma_s_per_scatterer(node, s_c_.data());
    const double* T0 = T_before(static_cast<int>(k));
    double* w = tmp_.data();
    segment_weights(B, T0, s_t_.data(), dt_[k], T_before_.data() + (k + 1) * B, w);
    multiply(B, w, s_s_.data(), w_ms_.data() + k * B);
    for (std::size_t c = 0; c < C; ++c) multiply(B, w, s_c_.data() + c * B, w_c_.data() + (k * C + c) * B);
  }
}

void ScatteringMarch::add_inscattering(int n, const double* nu, const float* phase, double mu_s0, int k0, int k1,
                                       double* L) const {
  if (mu0_.size() < static_cast<std::size_t>(std::max(0, n))) mu0_.resize(static_cast<std::size_t>(n));
  std::fill(mu0_.begin(), mu0_.begin() + std::max(0, n), mu_s0);
  add_inscattering(n, nu, mu0_.data(), phase, k0, k1, L);
}

// Views in tiles of kViewTile, all steps per tile: a tile's phase values,
// sums and the table rows its views read stay in the L1 cache.
void ScatteringMarch::add_inscattering(int n, const double* nu, const double* mu_s0, const float* phase, int k0,
                                       int k1, double* L) const {
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  const std::size_t N = static_cast<std::size_t>(std::max(0, n));
  for (std::size_t first = 0; first < N; first += kViewTile) {
    const std::size_t m = std::min(kViewTile, N - first);
    std::fill(L_f_.begin(), L_f_.begin() + static_cast<std::ptrdiff_t>(m * B), 0.0f);
    // A step of zero length adds exactly 0 (its weights are 0): skipped.  All
    // steps of a ray that starts on the ground and goes down are (the sky-
    // view table's ground rows for an observer at 0 m: half its rows).
    for (int k = std::max(0, k0); k < std::min(k1, steps_); ++k)
      if (dt_[static_cast<std::size_t>(k)] > 0.0)
        add_step(static_cast<std::size_t>(k), m, nu + first, mu_s0 + first, phase + first * C * B, L_f_.data());
    double* out = L + first * B;
    for (std::size_t j = 0; j < m * B; ++j) out[j] += L_f_[j];
  }
}

// One step for up to kViewTile views.
SKYFARM_LUT_SIMD_CLONES
void ScatteringMarch::add_step(std::size_t k, std::size_t n, const double* nu, const double* mu_s0, const float* phase,
                               float* L) const {
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  const TransmittanceLut::RadiusCoord rc = radius_[k];
  const double a = c_mu_[k], c = c_nu_[k];
  // Where each view's mu_s(t_k) falls in the transmittance and multiple-
  // scattering tables (u_T < 0: the planet hides the sun).
  const double ms_nodes = ms_ ? ms_->mu_s_samples() - 1 : 0.0;
  double *__restrict u_T = u_T_.data(), *__restrict u_ms = u_ms_.data();
  for (std::size_t i = 0; i < n; ++i) {
    const double mu_s = std::min(1.0, std::max(-1.0, a * mu_s0[i] + c * nu[i]));
    u_T[i] = transmittance_.mu_position(rc, mu_s);
    u_ms[i] = 0.5 * (mu_s + 1.0) * ms_nodes;  // MultipleScatteringLut::mu_s_position
  }
  const float* wc = w_c_.data() + k * C * B;
  const float* wms = w_ms_.data() + k * B;
  if (ms_ && (C == 1 || C == 2)) {  // Earth's air and aerosols, or one scatterer: one fused pass per view
    const float* wc1 = C == 2 ? wc + B : wc;  // C == 1: a zero second term
    const float c1 = C == 2 ? 1.0f : 0.0f;
    // Each view's nodes and fractions in both tables, in one vectorisable
    // pass (u_T < 0: node 0, unused), and the range of nodes the views fall
    // on: when they are fewer than the views, interpolate the tables to this
    // step's radius once (radius_rows) and each view along mu only.
    int *__restrict jt = node_T_.data(), *__restrict jm = node_ms_.data();
    float *__restrict ft = frac_T_.data(), *__restrict fm = frac_ms_.data();
    const int t_last = transmittance_.mu_samples() - 2, m_last = ms_->mu_s_samples() - 2;
    for (std::size_t i = 0; i < n; ++i) {
      const int t = std::min(static_cast<int>(std::max(u_T[i], 0.0)), t_last);  // TransmittanceLut::node_of
      const int m = std::min(static_cast<int>(u_ms[i]), m_last);
      jt[i] = t;
      jm[i] = m;
      ft[i] = static_cast<float>(u_T[i] - t);
      fm[i] = static_cast<float>(u_ms[i] - m);
    }
    int t_lo = t_last + 1, t_hi = -1, m_lo = m_last + 1, m_hi = -1;
    for (std::size_t i = 0; i < n; ++i) {
      if (u_T[i] >= 0.0) {
        t_lo = std::min(t_lo, jt[i]);
        t_hi = std::max(t_hi, jt[i]);
      }
      m_lo = std::min(m_lo, jm[i]);
      m_hi = std::max(m_hi, jm[i]);
    }
    const std::size_t t_rows = t_lo <= t_hi ? static_cast<std::size_t>(t_hi - t_lo + 2) : 0;
    const std::size_t m_rows = static_cast<std::size_t>(m_hi - m_lo + 2);
    if (t_rows + m_rows <= n) {
      float *T_rows = rows_T_.data(), *M_rows = rows_M_.data();
      if (t_rows > 0) transmittance_.radius_rows(rc, static_cast<std::size_t>(t_lo), t_rows, T_rows);
      ms_->altitude_rows(ms_altitude_[k], static_cast<std::size_t>(m_lo), m_rows, M_rows);
      const std::size_t p1 = C == 2 ? B : 0;
      // Each view's pass over the bins is short (32 bins: two AVX-512
      // iterations), so with the count known at compile time the loop is
      // straight-line code without its remainder handling.
      const auto views = [&](auto bins) __attribute__((always_inline)) {
        for (std::size_t i = 0; i < n; ++i) {
          const float* M = M_rows + static_cast<std::size_t>(jm[i] - m_lo) * B;
          if (u_T[i] >= 0.0) {
            const float* p = phase + i * C * B;
            add_source_rows(bins, L + i * B, wc, p, wc1, p + p1, c1,
                            T_rows + static_cast<std::size_t>(jt[i] - t_lo) * B, ft[i], M, fm[i], wms);
          } else {
            add_weighted_row(bins, L + i * B, M, fm[i], wms);
          }
        }
      };
      if (B == kDefaultBins)
        views(std::integral_constant<std::size_t, kDefaultBins>{});
      else
        views(B);
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const lut::BilinearF m = ms_->bilinear(ms_altitude_[k], u_ms[i]);
      if (u_T[i] >= 0.0) {
        const float* p = phase + i * C * B;
        add_source(B, L + i * B, wc, p, wc1, C == 2 ? p + B : p, c1, transmittance_.bilinear(rc, u_T[i]), wms, m);
      } else {
        m.weighted_add(bins_, wms, L + i * B);
      }
    }
    return;
  }
  float* w_phase = w_phase_.data();
  for (std::size_t i = 0; i < n; ++i) {  // the general case: any number of scatterers, with or without Psi_ms
    float* Li = L + i * B;
    const float* p = phase + i * C * B;
    if (u_T[i] >= 0.0 && C > 0) {
      for (std::size_t b = 0; b < B; ++b) w_phase[b] = wc[b] * p[b];
      for (std::size_t cc = 1; cc < C; ++cc)
        for (std::size_t b = 0; b < B; ++b) w_phase[b] += wc[cc * B + b] * p[cc * B + b];
      transmittance_.bilinear(rc, u_T[i]).weighted_add(bins_, w_phase, Li);
    }
    if (ms_) ms_->bilinear(ms_altitude_[k], u_ms[i]).weighted_add(bins_, wms, Li);
  }
}

void ScatteringMarch::add_ground(double nu, double mu_s0, double* L) const {
  if (!ends_on_ground_) return;
  const std::size_t B = static_cast<std::size_t>(bins_);
  const double R = medium_.planet_radius_m();
  const double mu_g = std::clamp((r0_ * mu_s0 + t_end_ * nu) / R, -1.0, 1.0);
  // Direct sun on the ground: E T_sun max(0, n . s); sky light: E I(mu_g).
  std::fill(tmp_.begin(), tmp_.end(), 0.0);
  if (mu_g > 0.0) {
    transmittance_.to_top(R, mu_g, tmp_.data());  // 0 if mu_g <= 0 anyway
    for (std::size_t b = 0; b < B; ++b) tmp_[b] *= mu_g;
  }
  if (gi_) gi_->lookup_add(mu_g, tmp_.data());
  const double* T_end = T_before(steps_);
  const std::vector<double>& albedo = medium_.ground_albedo();
  for (std::size_t b = 0; b < B; ++b) L[b] += T_end[b] * albedo[b] * kInvPi * tmp_[b];
}

void ScatteringMarch::add_bands(const MultipleScatteringBands& bands, double nu, double mu_s0, double* L) const {
  if (bands.max_band() == 0) return;
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  band_coefficients_.resize(static_cast<std::size_t>(bands.harmonics()) * B);
  const double R = medium_.planet_radius_m();
  for (std::size_t k = 0; k < static_cast<std::size_t>(steps_); ++k) {
    if (!(dt_[k] > 0.0)) continue;
    const double rk = r0_ / c_mu_[k];
    const double mu_v = std::clamp(c_mu_[k] * mu_ + c_nu_[k], -1.0, 1.0);
    const double mu_s = std::clamp(c_mu_[k] * mu_s0 + c_nu_[k] * nu, -1.0, 1.0);
    const double sin_s = std::sqrt(std::max(0.0, (1.0 - mu_s) * (1.0 + mu_s)));
    const double sin_v = std::sqrt(std::max(0.0, (1.0 - mu_v) * (1.0 + mu_v)));
    // (A sun at the zenith leaves only the m = 0 harmonics, whatever x_v.)
    const double x_v = sin_s > 1e-9 ? std::clamp((nu - mu_v * mu_s) / sin_s, -sin_v, sin_v) : 0.0;
    bands.coefficients(rk - R, mu_s, band_coefficients_.data());
    bands.add_source(band_coefficients_.data(), mu_v, x_v, w_c_.data() + k * C * B, L);
  }
}

}  // namespace skyfarm

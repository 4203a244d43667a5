#include "tests/support/adding_doubling.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace skyfarm::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A dense n x n matrix, row-major.
struct Matrix {
  int n = 0;
  std::vector<double> a;
  explicit Matrix(int size = 0) : n(size), a(static_cast<std::size_t>(size) * size, 0.0) {}
  double& operator()(int i, int j) { return a[static_cast<std::size_t>(i) * n + j]; }
  double operator()(int i, int j) const { return a[static_cast<std::size_t>(i) * n + j]; }
};

Matrix operator*(const Matrix& x, const Matrix& y) {
  Matrix z(x.n);
  for (int i = 0; i < x.n; ++i)
    for (int k = 0; k < x.n; ++k) {
      const double xik = x(i, k);
      for (int j = 0; j < x.n; ++j) z(i, j) += xik * y(k, j);
    }
  return z;
}
Matrix operator+(Matrix x, const Matrix& y) {
  for (std::size_t i = 0; i < x.a.size(); ++i) x.a[i] += y.a[i];
  return x;
}
std::vector<double> operator*(const Matrix& x, const std::vector<double>& v) {
  std::vector<double> out(x.n, 0.0);
  for (int i = 0; i < x.n; ++i)
    for (int j = 0; j < x.n; ++j) out[i] += x(i, j) * v[j];
  return out;
}
std::vector<double> operator+(std::vector<double> x, const std::vector<double>& y) {
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += y[i];
  return x;
}
// diag(e) * x and x * diag(e).
Matrix scale_rows(const std::vector<double>& e, Matrix x) {
  for (int i = 0; i < x.n; ++i)
    for (int j = 0; j < x.n; ++j) x(i, j) *= e[i];
  return x;
}
Matrix scale_columns(Matrix x, const std::vector<double>& e) {
  for (int i = 0; i < x.n; ++i)
    for (int j = 0; j < x.n; ++j) x(i, j) *= e[j];
  return x;
}
std::vector<double> scale(const std::vector<double>& e, std::vector<double> v) {
  for (std::size_t i = 0; i < v.size(); ++i) v[i] *= e[i];
  return v;
}

// Solves (I - Q) X = B and (I - Q) x = b in place (B n x n, b the sun's
// column), Gaussian elimination with partial pivoting.
void solve_identity_minus(const Matrix& Q, Matrix& B, std::vector<double>& b) {
  const int n = Q.n;
  Matrix A(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = (i == j ? 1.0 : 0.0) - Q(i, j);
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(A(r, c)) > std::abs(A(p, c))) p = r;
    if (p != c) {
      for (int j = 0; j < n; ++j) {
        std::swap(A(c, j), A(p, j));
        std::swap(B(c, j), B(p, j));
      }
      std::swap(b[c], b[p]);
    }
    for (int r = c + 1; r < n; ++r) {
      const double f = A(r, c) / A(c, c);
      if (f == 0.0) continue;
      for (int j = c; j < n; ++j) A(r, j) -= f * A(c, j);
      for (int j = 0; j < n; ++j) B(r, j) -= f * B(c, j);
      b[r] -= f * b[c];
    }
  }
  for (int c = n - 1; c >= 0; --c) {
    for (int j = 0; j < n; ++j) {
      double s = B(c, j);
      for (int k = c + 1; k < n; ++k) s -= A(c, k) * B(k, j);
      B(c, j) = s / A(c, c);
    }
    double s = b[c];
    for (int k = c + 1; k < n; ++k) s -= A(c, k) * b[k];
    b[c] = s / A(c, c);
  }
}

// P_0..P_lmax at x by the three-term recurrence.
std::vector<double> legendre(int lmax, double x) {
  std::vector<double> p(lmax + 1);
  p[0] = 1.0;
  if (lmax >= 1) p[1] = x;
  for (int l = 2; l <= lmax; ++l) p[l] = ((2.0 * l - 1.0) * x * p[l - 1] - (l - 1.0) * p[l - 2]) / l;
  return p;
}

}  // namespace

void gauss_legendre(int n, double a, double b, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton from Tricomi's initial guess for the i-th root of P_n.
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int l = 2; l <= n; ++l) {
        const double p2 = ((2.0 * l - 1.0) * x * p1 - (l - 1.0) * p0) / l;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0, p1 = x;
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // Recompute the derivative at the converged root for the weight.
    double p0 = 1.0, p1 = x;
    for (int l = 2; l <= n; ++l) {
      const double p2 = ((2.0 * l - 1.0) * x * p1 - (l - 1.0) * p0) / l;
      p0 = p1;
      p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    nodes[i] = 0.5 * (a + b) + 0.5 * (b - a) * (-x);  // increasing order
    weights[i] = 0.5 * (b - a) * w;
  }
}

// chi_l = 2 pi int_{-1}^{1} p(mu) P_l(mu) dmu.  The integral runs over a grid
// in scattering angle (0.01 deg up to 2 deg, 0.05 deg to 20, 0.25 deg beyond)
// joined with a tabulated phase's own knots (where its interpolant has kinks),
// 8 Gauss points per interval: exact for the piecewise-linear tables up to
// l ~ 14 per interval and resolving P_l for l <= 256 everywhere.
std::vector<double> phase_legendre_moments(const PhaseFunction& phase, int lmax) {
  std::vector<double> mu_breaks;
  auto add = [&](double from_deg, double to_deg, double step) {
    for (double a = from_deg; a < to_deg - 1e-9; a += step) mu_breaks.push_back(std::cos(a * kPi / 180.0));
  };
  add(0.0, 2.0, 0.01);
  add(2.0, 20.0, 0.05);
  add(20.0, 180.0, 0.25);
  mu_breaks.push_back(-1.0);
  if (const auto* table = std::get_if<TabulatedPhase>(&phase.model())) {
    mu_breaks.insert(mu_breaks.end(), table->table->mu.begin(), table->table->mu.end());
  }
  std::sort(mu_breaks.begin(), mu_breaks.end());
  mu_breaks.erase(std::unique(mu_breaks.begin(), mu_breaks.end()), mu_breaks.end());

  std::vector<double> x, w;
  gauss_legendre(8, 0.0, 1.0, x, w);
  std::vector<double> chi(lmax + 1, 0.0);
  for (std::size_t k = 0; k + 1 < mu_breaks.size(); ++k) {
    const double lo = mu_breaks[k], hi = mu_breaks[k + 1], h = hi - lo;
    if (h <= 0.0) continue;
    for (int q = 0; q < 8; ++q) {
      const double mu = lo + h * x[q];
      const double f = 2.0 * kPi * phase.eval(mu) * h * w[q];
      const std::vector<double> p = legendre(lmax, mu);
      for (int l = 0; l <= lmax; ++l) chi[l] += f * p[l];
    }
  }
  return chi;
}

SlabFluxes adding_doubling_slab(double tau, double omega, const PhaseFunction& phase, double mu0, int streams) {
  if (!(tau > 0.0) || !std::isfinite(tau)) throw std::invalid_argument("adding_doubling_slab: tau must be > 0");
  if (!(omega >= 0.0 && omega <= 1.0)) throw std::invalid_argument("adding_doubling_slab: omega outside [0, 1]");
  if (!(mu0 > 0.0 && mu0 <= 1.0)) throw std::invalid_argument("adding_doubling_slab: mu0 outside (0, 1]");
  if (streams < 4 || streams > 256 || streams % 2 != 0) {
    std::ostringstream msg;
    msg << "adding_doubling_slab: streams " << streams << " must be even, 4-256";
    throw std::invalid_argument(msg.str());
  }
  const int n = streams / 2;

  // Delta-M (Wiscombe 1977): moments 0..streams-1 kept, f = chi_streams.
  std::vector<double> chi = phase_legendre_moments(phase, streams);
  // The table's own normalisation (chi_0 = 1 to its quadrature).
  for (double& c : chi) c /= chi[0];
  const double f = std::max(0.0, chi[streams]);
  const double tau_s = (1.0 - omega * f) * tau;
  const double omega_s = omega * (1.0 - f) / (1.0 - omega * f);
  chi.resize(streams);
  for (double& c : chi) c = (c - f) / (1.0 - f);

  // Double-Gauss quadrature on (0, 1].
  std::vector<double> mu, w;
  gauss_legendre(n, 0.0, 1.0, mu, w);

  // Azimuth-averaged phase between the quadrature directions (and the sun):
  // P0(mu, mu') = sum_l (2l+1) chi_l P_l(mu) P_l(mu'), 4 pi normalised.
  // plus: both directions down (transmission); minus: one up, one down.
  const int lmax = streams - 1;
  std::vector<std::vector<double>> p_mu(n);
  for (int i = 0; i < n; ++i) p_mu[i] = legendre(lmax, mu[i]);
  const std::vector<double> p_sun = legendre(lmax, mu0);
  auto p0 = [&](const std::vector<double>& a, const std::vector<double>& b, bool reflect) {
    double s = 0.0;
    for (int l = 0; l <= lmax; ++l) s += (2.0 * l + 1.0) * chi[l] * a[l] * b[l] * ((reflect && (l & 1)) ? -1.0 : 1.0);
    return s;
  };

  // The initial layer: tau_0 = tau_s / 2^doublings, <= 2^-20 tau_s and <= 1e-8.
  int doublings = 20;
  while (tau_s / std::ldexp(1.0, doublings) > 1e-8) ++doublings;
  const double t0 = tau_s / std::ldexp(1.0, doublings);

  // Exact single scattering in the thin layer.  Units: a diffuse incident
  // radiance I_j at -mu_j contributes w_j I_j to the source; the sun's beam is
  // an extra column of flux 2 pi at normal incidence (so that its "w I" is 1):
  //   R_ij = omega/2 P0(up i, down j) w_j mu_j/(mu_i+mu_j) (1 - exp(-t0 (1/mu_i + 1/mu_j)))
  //   T_ij = omega/2 P0(down i, down j) w_j (1/mu_i) int_0^t0 exp(-t/mu_j - (t0-t)/mu_i) dt
  auto transmit_kernel = [&](double mi, double mj) {
    if (std::abs(mi - mj) < 1e-12 * mi) return t0 / mi * std::exp(-t0 / mi);
    return mj / (mj - mi) * (std::exp(-t0 / mj) - std::exp(-t0 / mi));
  };
  auto reflect_kernel = [&](double mi, double mj) { return mj / (mi + mj) * -std::expm1(-t0 * (1.0 / mi + 1.0 / mj)); };
  Matrix R(n), T(n);
  std::vector<double> Rs(n), Ts(n), E(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      R(i, j) = 0.5 * omega_s * p0(p_mu[i], p_mu[j], true) * w[j] * reflect_kernel(mu[i], mu[j]);
      T(i, j) = 0.5 * omega_s * p0(p_mu[i], p_mu[j], false) * w[j] * transmit_kernel(mu[i], mu[j]);
    }
    Rs[i] = 0.5 * omega_s * p0(p_mu[i], p_sun, true) * reflect_kernel(mu[i], mu0);
    Ts[i] = 0.5 * omega_s * p0(p_mu[i], p_sun, false) * transmit_kernel(mu[i], mu0);
    E[i] = std::exp(-t0 / mu[i]);
  }
  double e0 = std::exp(-t0 / mu0);

  // Doubling (Hansen & Travis 1974, eqs. 3.11-3.15 with the direct beam kept
  // apart): two identical layers, Q = R R, A = (I - Q)^-1,
  //   D = A (T + Q E), U = R E + R D, R2 = R + E U + T U, T2 = E D + T E + T D,
  // and the sun's column alike with the scalar e0.
  for (int k = 0; k < doublings; ++k) {
    const Matrix Q = R * R;
    Matrix D = T + scale_columns(Q, E);
    std::vector<double> Ds = R * Rs;
    for (int i = 0; i < n; ++i) Ds[i] = Ts[i] + Ds[i] * e0;
    solve_identity_minus(Q, D, Ds);
    const Matrix U = scale_columns(R, E) + R * D;
    std::vector<double> Us = R * Ds;
    for (int i = 0; i < n; ++i) Us[i] += Rs[i] * e0;
    const Matrix R2 = R + scale_rows(E, U) + T * U;
    const Matrix T2 = scale_rows(E, D) + scale_columns(T, E) + T * D;
    std::vector<double> Rs2 = Rs + scale(E, Us) + T * Us;
    std::vector<double> Ts2 = scale(E, Ds) + T * Ds;
    for (int i = 0; i < n; ++i) Ts2[i] += Ts[i] * e0;
    R = R2;
    T = T2;
    Rs = std::move(Rs2);
    Ts = std::move(Ts2);
    for (double& e : E) e *= e;
    e0 *= e0;
  }

  SlabFluxes out;
  out.delta_m_fraction = f;
  out.mu = mu;
  for (int i = 0; i < n; ++i) {
    out.reflectance += w[i] * mu[i] * Rs[i] / mu0;
    out.diffuse_transmittance += w[i] * mu[i] * Ts[i] / mu0;
    // pi I / (mu0 E0) with E0 = 2 pi.
    out.reflection_function.push_back(Rs[i] / (2.0 * mu0));
    out.transmission_function.push_back(Ts[i] / (2.0 * mu0));
  }
  // As DISORT reports them: the true direct beam exp(-tau/mu0), and as
  // diffuse what the delta-M solution transmits beyond it (the truncated
  // forward peak is diffuse light close to the sun).
  out.direct_transmittance = std::exp(-tau / mu0);
  out.diffuse_transmittance += e0 - out.direct_transmittance;
  return out;
}

}  // namespace skyfarm::testing

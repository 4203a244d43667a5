// Phase functions (see phase_function.h for the conventions and parameters).
#include "common/atmosphere/phase_function.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/core/constants.h"
#include "common/core/math.h"
#include "common/sampling/warps.h"

namespace skyfarm {
namespace {

constexpr double k3Over16Pi = 3.0 / (16.0 * kPi);
constexpr double k3Over8Pi = 3.0 / (8.0 * kPi);
constexpr double k2Pi = 2.0 * kPi;

std::string number(double x) {
  std::ostringstream out;
  out.precision(12);
  out << x;
  return out.str();
}

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

void check_asymmetry(const char* model, double g) {
  if (!(std::isfinite(g) && std::abs(g) < 1.0)) {
    fail(std::string(model) + " phase function: g must be finite and in (-1, 1), got " + number(g));
  }
}

// s = 1 + g^2 - 2 g mu, the squared distance-like denominator of the
// Henyey-Greenstein and Cornette-Shanks functions, written as a sum of
// non-negative terms so that it keeps full relative precision where it is
// small (|g| -> 1 and mu -> sign(g)):
//   s = (1 - g)^2 + 2 g (1 - mu)   for g >= 0,
//   s = (1 + g)^2 - 2 g (1 + mu)   for g <  0.
double hg_s(double g, double mu) {
  return g >= 0.0 ? sqr(1.0 - g) + 2.0 * g * (1.0 - mu) : sqr(1.0 + g) - 2.0 * g * (1.0 + mu);
}

// The Cornette-Shanks CDF in its cancellation-free form (derivation above
// CornetteShanksPhase::cdf).  Its complement is 1 - F_g(mu) = F_{-g}(-mu)
// (p_g(mu) = p_{-g}(-mu)), which keeps full relative precision in the upper
// tail too.
double cornette_shanks_cdf(double g, double mu) {
  mu = clamp_cos(mu);
  const double t = std::sqrt(hg_s(g, mu));
  const double t0 = 1.0 + g;
  const double d = 2.0 * (1.0 + mu) / (t0 + t);
  const double e = d * t0;
  const double poly = 24.0 - 12.0 * e + 4.0 * e * e - g * e * d * d;
  return std::clamp((1.0 - g) * d * poly / (16.0 * (2.0 + g * g) * t), 0.0, 1.0);
}

}  // namespace

// ---------------------------------------------------------------------------
// Rayleigh with depolarisation (Chandrasekhar 1950, "Radiative Transfer" §18;
// Bucholtz 1995, Appl. Opt. 34(15), eq. 12-13), for unpolarised light:
//   gamma = rho_n / (2 - rho_n),
//   p(mu) = 3 / (16 pi (1 + 2 gamma)) [(1 + 3 gamma) + (1 - gamma) mu^2].
// rho_n = 0 gives 3/(16 pi) (1 + mu^2); rho_n = 1 (gamma = 1) is isotropic.
double RayleighPhase::eval(double mu) const {
  mu = clamp_cos(mu);
  return k3Over16Pi / (1.0 + 2.0 * gamma) * ((1.0 + 3.0 * gamma) + (1.0 - gamma) * mu * mu);
}

// Inverse CDF of the Rayleigh phase function.  With A = 1 + 3 gamma and
// B = (1 - gamma)/3 the CDF 2 pi int_{-1}^{mu} p is
//   F(mu) = [A (mu + 1) + B (mu^3 + 1)] / (2 (A + B)),
// so F(mu) = u is the depressed cubic  B mu^3 + A mu = (A + B) xi, xi = 2u - 1.
// Its discriminant is positive (A, B >= 0), so it has one real root, taken in
// the hyperbolic form of Cardano's solution (no cancellation, odd in xi,
// valid for every gamma < 1 including 0):
//   k = sqrt(A / (3B)) = sqrt((1 + 3 gamma) / (1 - gamma)),
//   r = 2 (1 + 2 gamma) xi / ((1 - gamma) k^3),
//   mu = 2 k sinh(asinh(r) / 3).
// gamma = 0: mu = 2 sinh(asinh(2 xi) / 3); gamma = 1: B = 0 and mu = xi.
double RayleighPhase::sample_cos_theta(double u) const {
  const double xi = 2.0 * std::clamp(u, 0.0, 1.0) - 1.0;
  if (gamma >= 1.0) return xi;
  const double k = std::sqrt((1.0 + 3.0 * gamma) / (1.0 - gamma));
  const double r = 2.0 * (1.0 + 2.0 * gamma) * xi / ((1.0 - gamma) * k * k * k);
  return clamp_cos(2.0 * k * std::sinh(std::asinh(r) / 3.0));
}

// ---------------------------------------------------------------------------
// Henyey & Greenstein (1941), ApJ 93, 70:
//   p(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^{3/2}),
// with the denominator in the cancellation-free form hg_s().
double HenyeyGreensteinPhase::eval(double mu) const {
  mu = clamp_cos(mu);
  const double s = hg_s(g, mu);
  return kInv4Pi * (1.0 - g) * (1.0 + g) / (s * std::sqrt(s));
}

// Inverse CDF of Henyey-Greenstein.  F(mu) = (1 - g^2)/(2g) [s^{-1/2} - 1/(1+g)]
// inverts to the textbook  mu = (1 + g^2 - ((1 - g^2)/(1 - g + 2 g u))^2) / (2g)
// (pbrt-v4 SampleHenyeyGreenstein, with pbrt's opposite direction convention),
// which divides by g and cancels as g -> 0 (pbrt switches to uniform below
// |g| = 1e-3 and clamps |g| <= 0.99 because of it).  Expanding the square over
// the common denominator D, the 1/(2g) cancels exactly:
//   u <  1/2:  D = 1 - g + 2 g u,  mu = [2 (1 + g^2) u (1 - g + g u) - (1 - g)^2] / D^2,
//   u >= 1/2:  v = 1 - u (exact),  D = 1 + g - 2 g v,
//              mu = [(1 + g)^2 - 2 (1 + g^2)(1 + g) v + 2 g (1 + g^2) v^2] / D^2
// (the same polynomial in v; the second form avoids the cancellation of the
// first near u = 1 when g -> -1, where the numerator tends to (1 + g)^2).
// In both every term is O(D^2), so mu has an absolute error of a few ulps for
// every g in (-1, 1), g = 0 (mu = 2u - 1) included: no threshold is needed and
// the sample density equals eval() for all g.
double HenyeyGreensteinPhase::sample_cos_theta(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  const double c = 1.0 + g * g;
  double numerator, D;
  if (u < 0.5) {
    D = 1.0 - g + 2.0 * g * u;
    numerator = 2.0 * c * u * (1.0 - g + g * u) - sqr(1.0 - g);
  } else {
    const double v = 1.0 - u;
    D = 1.0 + g - 2.0 * g * v;
    numerator = sqr(1.0 + g) - 2.0 * c * (1.0 + g) * v + 2.0 * g * c * v * v;
  }
  return clamp_cos(numerator / (D * D));
}

// ---------------------------------------------------------------------------
// Cornette & Shanks (1992), Appl. Opt. 31(16), eq. 4 (also Bruneton 2017,
// functions.glsl MiePhaseFunction):
//   p(mu) = 3/(8 pi) (1 - g^2)(1 + mu^2) / ((2 + g^2)(1 + g^2 - 2 g mu)^{3/2}).
double CornetteShanksPhase::eval(double mu) const {
  mu = clamp_cos(mu);
  const double s = hg_s(g, mu);
  return k3Over8Pi * (1.0 - g) * (1.0 + g) * (1.0 + mu * mu) / ((2.0 + g * g) * s * std::sqrt(s));
}

// Mean cosine of Cornette-Shanks (integrating mu p(mu) over the sphere):
//   <mu> = 3 g (4 + g^2) / (5 (2 + g^2)).
double CornetteShanksPhase::mean_cosine() const { return 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g)); }

// Exact CDF of Cornette-Shanks.  F(mu) = (3/4)(1-g^2)/(2+g^2) int_{-1}^{mu} (1+x^2) s^{-3/2} dx
// with s = 1 + g^2 - 2 g x.  Substituting x = (c - s)/(2g), c = 1 + g^2, the
// integrand becomes the quadratic (s^2 - 2 c s + c^2 + 4 g^2)/(4 g^2) times
// s^{-3/2} ds/(-2g), with antiderivative
//   G(s) = (2/3) s^{3/2} - 4 c s^{1/2} - 2 (c^2 + 4 g^2) s^{-1/2},
//   F(mu) = -3 (1 - g^2) / (32 g^3 (2 + g^2)) [G(s(mu)) - G((1 + g)^2)].
// That form loses ~3 log10(1/|g|) digits to cancellation.  With t = sqrt(s),
// t0 = 1 + g and t0 - t = 2 g (1 + mu)/(t0 + t) = g d, the difference factors
// exactly and the g^3 cancels (verified symbolically):
//   d = 2 (1 + mu) / (t0 + t)  in [0, 2],   e = d t0,
//   F(mu) = (1 - g) d (24 - 12 e + 4 e^2 - g e d^2) / (16 (2 + g^2) t).
// Every term is at most 64 and the polynomial stays above 13, so F has full relative
// precision for all g in (-1, 1) and mu in [-1, 1]; at g = 0 it is the
// Rayleigh (gamma = 0) CDF (6d - 3d^2 + d^3)/8 with d = 1 + mu.
double CornetteShanksPhase::cdf(double mu) const { return cornette_shanks_cdf(g, mu); }

// Inverse of the exact CDF above by safeguarded Newton-bisection on [-1, 1]
// (F' = 2 pi p), started from the Henyey-Greenstein sample of the same g (the
// same s^{-3/2} peak).  For u > 1/2 it solves the complement,
// F_{-g}(-mu) = 1 - u (1 - u exact there), so both tails keep full relative
// precision.  A Newton step that leaves the bracket is replaced by bisection,
// so it always converges.  It stops when the residual is at the rounding level
// of the CDF (16 eps min(u, 1 - u)), when the step or the bracket is down to
// ulps, or when the root lies within rounding of a bracket end; mu is then as
// exact as a double near the root allows.  Exact for every g in (-1, 1), g = 0
// included.
double CornetteShanksPhase::sample_cos_theta(double u) const {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double xi = std::clamp(u, 0.0, 1.0);
  const bool upper = xi > 0.5;
  const double target = upper ? 1.0 - xi : xi;
  // F(mu) - xi, evaluated from the nearer end.
  const auto residual_at = [&](double m) {
    return upper ? target - cornette_shanks_cdf(-g, -m) : cornette_shanks_cdf(g, m) - target;
  };
  double lo = -1.0, hi = 1.0;
  double mu = HenyeyGreensteinPhase{g}.sample_cos_theta(xi);
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double residual = residual_at(mu);
    if (std::abs(residual) <= 16.0 * eps * target) break;
    if (residual < 0.0) {
      lo = mu;
    } else {
      hi = mu;
    }
    double next = mu - residual / (k2Pi * eval(mu));
    if (next == lo || next == hi) {  // the root is within rounding of a bracket end
      mu = next;
      break;
    }
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // also catches NaN
    const double step = std::abs(next - mu);
    mu = next;
    if (step <= 2.0 * eps * std::abs(mu) || hi - lo <= 4.0 * eps) break;
  }
  return clamp_cos(mu);
}

// ---------------------------------------------------------------------------
// Tabulated phase function, linear in mu between the knots:
//   p(mu) = p_i + (p_{i+1} - p_i) (mu - mu_i) / (mu_{i+1} - mu_i),  mu_i <= mu <= mu_{i+1}.
double TabulatedPhase::eval(double mu) const {
  const auto& mus = table->mu;
  mu = clamp_cos(mu);
  const std::size_t n = mus.size();
  const std::size_t upper = static_cast<std::size_t>(std::upper_bound(mus.begin(), mus.end(), mu) - mus.begin());
  const std::size_t i = std::min(upper == 0 ? 0 : upper - 1, n - 2);
  const double x = std::clamp((mu - mus[i]) / (mus[i + 1] - mus[i]), 0.0, 1.0);
  return std::max(0.0, lerp(x, table->p[i], table->p[i + 1]));
}

// Exact sampling of the piecewise-linear density: binary search of u in the
// knot CDF, then in the segment (density a -> b over [0, 1] in x) solve
//   a x + (b - a) x^2 / 2 = r (a + b) / 2,  r = (u - F_i)/(F_{i+1} - F_i),
// by the cancellation-free root  x = r (a + b) / (a + sqrt((1 - r) a^2 + r b^2))
// (also right for a = b and for a = 0).
double TabulatedPhase::sample_cos_theta(double u) const {
  const auto& mus = table->mu;
  const auto& cdf = table->cdf;
  const auto& p = table->p;
  const double xi = std::clamp(u, 0.0, 1.0);
  const std::size_t n = mus.size();
  // Last knot with cdf <= xi: its segment has positive mass whenever xi < 1.
  const std::size_t upper = static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), xi) - cdf.begin());
  const std::size_t i = std::min(upper == 0 ? 0 : upper - 1, n - 2);
  const double mass = cdf[i + 1] - cdf[i];
  const double r = mass > 0.0 ? std::clamp((xi - cdf[i]) / mass, 0.0, 1.0) : 0.0;
  const double a = p[i], b = p[i + 1];
  const double denominator = a + std::sqrt((1.0 - r) * a * a + r * b * b);
  const double x = denominator > 0.0 ? std::clamp(r * (a + b) / denominator, 0.0, 1.0) : r;
  return std::clamp(mus[i] + x * (mus[i + 1] - mus[i]), mus[i], mus[i + 1]);
}

// ---------------------------------------------------------------------------
// Factories.

PhaseFunction PhaseFunction::rayleigh(double depolarization) {
  if (!(std::isfinite(depolarization) && depolarization >= 0.0 && depolarization <= 1.0)) {
    fail("rayleigh phase function: depolarization must be in [0, 1], got " + number(depolarization));
  }
  RayleighPhase model;
  model.depolarization = depolarization;
  model.gamma = depolarization / (2.0 - depolarization);
  return PhaseFunction(model);
}

PhaseFunction PhaseFunction::henyey_greenstein(double g) {
  check_asymmetry("henyey_greenstein", g);
  return PhaseFunction(HenyeyGreensteinPhase{g});
}

PhaseFunction PhaseFunction::cornette_shanks(double g) {
  check_asymmetry("cornette_shanks", g);
  return PhaseFunction(CornetteShanksPhase{g});
}

// Tabulated: knots mu_i = cos(theta_i) in increasing mu (the table reversed),
// ends set to exactly -1 and 1; normalisation by the exact integral of the
// piecewise-linear interpolant (trapezoids in mu):
//   N = 2 pi sum_i (mu_{i+1} - mu_i)(v_i + v_{i+1})/2,   p_i = v_i / N;
// mean cosine per segment of width w = mu_{i+1} - mu_i:
//   int mu p dmu = w/6 [p_i (2 mu_i + mu_{i+1}) + p_{i+1} (mu_i + 2 mu_{i+1})].
PhaseFunction PhaseFunction::tabulated(std::span<const double> angles_deg, std::span<const double> values) {
  const std::string what = "phase table: ";
  if (angles_deg.size() != values.size()) {
    fail(what + "angles_deg and values must have the same length, got " + std::to_string(angles_deg.size()) + " and " +
         std::to_string(values.size()));
  }
  const std::size_t n = angles_deg.size();
  if (n < 2) fail(what + "needs at least 2 angles (0 and 180 degrees), got " + std::to_string(n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(angles_deg[i])) {
      fail(what + "angles_deg[" + std::to_string(i) + "] is not finite (" + number(angles_deg[i]) + ")");
    }
    if (!std::isfinite(values[i])) {
      fail(what + "values[" + std::to_string(i) + "] is not finite (" + number(values[i]) + ")");
    }
    if (values[i] < 0.0) {
      fail(what + "values[" + std::to_string(i) + "] is negative (" + number(values[i]) + ")");
    }
    if (i > 0 && !(angles_deg[i] > angles_deg[i - 1])) {
      fail(what + "angles_deg must be strictly increasing, but angles_deg[" + std::to_string(i) +
           "] = " + number(angles_deg[i]) + " follows " + number(angles_deg[i - 1]));
    }
  }
  if (angles_deg.front() != 0.0) fail(what + "angles_deg must start at 0, got " + number(angles_deg.front()));
  if (angles_deg.back() != 180.0) fail(what + "angles_deg must end at 180, got " + number(angles_deg.back()));
  if (std::all_of(values.begin(), values.end(), [](double v) { return v == 0.0; })) {
    fail(what + "all values are zero");
  }

  auto table = std::make_shared<TabulatedPhase::Table>();
  table->mu.resize(n);
  table->p.resize(n);
  table->cdf.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = n - 1 - i;  // increasing mu = decreasing angle
    table->mu[i] = std::cos(angles_deg[k] * kDegToRad);
    table->p[i] = values[k];
  }
  table->mu.front() = -1.0;
  table->mu.back() = 1.0;
  for (std::size_t i = 1; i < n; ++i) {
    if (!(table->mu[i] > table->mu[i - 1])) {
      fail(what + "angles_deg " + number(angles_deg[n - 1 - i]) + " and " + number(angles_deg[n - i]) +
           " are too close to be told apart in cos(theta)");
    }
  }

  // Unnormalised masses, then everything divided by the total.
  double total = 0.0, first_moment = 0.0;
  table->cdf[0] = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double w = table->mu[i + 1] - table->mu[i];
    const double a = table->p[i], b = table->p[i + 1];
    total += k2Pi * w * 0.5 * (a + b);
    first_moment +=
        k2Pi * w / 6.0 * (a * (2.0 * table->mu[i] + table->mu[i + 1]) + b * (table->mu[i] + 2.0 * table->mu[i + 1]));
    table->cdf[i + 1] = total;
  }
  for (std::size_t i = 0; i < n; ++i) {
    table->p[i] /= total;
    table->cdf[i] /= total;
  }
  table->cdf.back() = 1.0;
  table->mean_cosine = first_moment / total;
  return PhaseFunction(TabulatedPhase{std::move(table)});
}

PhaseFunction PhaseFunction::from_spec(const PhaseSpec& spec) {
  struct Visitor {
    PhaseFunction operator()(const RayleighPhaseSpec& s) const { return rayleigh(s.depolarization); }
    PhaseFunction operator()(const HenyeyGreensteinPhaseSpec& s) const { return henyey_greenstein(s.g); }
    PhaseFunction operator()(const CornetteShanksPhaseSpec& s) const { return cornette_shanks(s.g); }
    PhaseFunction operator()(const TablePhaseSpec& s) const { return tabulated(s.angles_deg, s.values); }
  };
  return std::visit(Visitor{}, spec);
}

// ---------------------------------------------------------------------------
// Dispatch.

double PhaseFunction::eval(double cos_theta) const {
  return std::visit([cos_theta](const auto& m) { return m.eval(cos_theta); }, model_);
}

double PhaseFunction::sample_cos_theta(double u) const {
  return std::visit([u](const auto& m) { return m.sample_cos_theta(u); }, model_);
}

double PhaseFunction::mean_cosine() const {
  return std::visit([](const auto& m) { return m.mean_cosine(); }, model_);
}

// Scattered propagation direction: mu from u1, phi = 2 pi u2, in the frame whose
// +z is the incident propagation direction (Duff et al. 2017, warps.h).
// sin(theta) = sqrt((1 - mu)(1 + mu)) keeps precision near mu = +-1.
glm::dvec3 PhaseFunction::sample_direction(const glm::dvec3& propagation, double u1, double u2) const {
  const double mu = sample_cos_theta(u1);
  const double sin_theta = safe_sqrt((1.0 - mu) * (1.0 + mu));
  const double phi = k2Pi * u2;
  return Frame(propagation).to_world({sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu});
}

std::string_view PhaseFunction::name() const {
  struct Visitor {
    std::string_view operator()(const RayleighPhase&) const { return "rayleigh"; }
    std::string_view operator()(const HenyeyGreensteinPhase&) const { return "henyey_greenstein"; }
    std::string_view operator()(const CornetteShanksPhase&) const { return "cornette_shanks"; }
    std::string_view operator()(const TabulatedPhase&) const { return "table"; }
  };
  return std::visit(Visitor{}, model_);
}

}  // namespace skyfarm

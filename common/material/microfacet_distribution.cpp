#include "common/material/microfacet_distribution.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace skyfarm::material {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSqrtPi = 1.77245385090551602730;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The squared tangent of w's polar angle weighted by the roughness along w's
// azimuth: alpha(phi)^2 tan^2(theta), with alpha(phi)^2 = cos^2(phi) alpha_x^2
// + sin^2(phi) alpha_y^2 written in Cartesian form.  +infinity for w.z == 0.
double alpha2_tan2(const glm::dvec3& w, double alpha_x, double alpha_y) {
  const double num = alpha_x * alpha_x * w.x * w.x + alpha_y * alpha_y * w.y * w.y;
  const double z2 = w.z * w.z;
  if (z2 == 0.0) return num > 0.0 ? kInfinity : 0.0;
  return num / z2;
}

// Beckmann's Lambda as a function of a = 1 / (alpha(phi) tan(theta)) > 0:
// (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)), with erf(a) - 1 written as
// -erfc(a): near normal incidence (large a) the two terms cancel to a
// fraction ~1/(2a^2) of their size, so about 2a^2 ulps of relative precision
// are lost (3e-13 at the cut-off a = 26), instead of everything to erf(a) ~ 1.
double beckmann_lambda_of_a(double a) {
  if (a == 0.0) return kInfinity;
  if (a > 26.0) return 0.0;  // exp(-a^2) < 1e-293: Lambda underflows to 0
  const double lambda = -0.5 * std::erfc(a) + std::exp(-a * a) / (2.0 * a * kSqrtPi);
  return std::max(lambda, 0.0);
}

// The Beckmann visible-slope CDF (unnormalised) for a standard (alpha = 1)
// surface seen from a direction whose cot(theta) is a:
//   F(x) = integral_{-inf}^{x} (a - t) exp(-t^2) dt
//        = a sqrt(pi)/2 erfc(-x) + exp(-x^2)/2,     x <= a.
// It follows from the visible-slope density (a - x)+ P22(x, y) with the
// separable P22 = exp(-x^2 - y^2) / pi (Heitz & d'Eon 2014, "Importance
// sampling microfacet-based BSDFs using the distribution of visible normals",
// the slope form of the visible normal distribution); it holds for a of
// either sign, i.e. for directions above and below the macro surface.
double beckmann_slope_cdf(double x, double a) {
  return 0.5 * a * kSqrtPi * std::erfc(-x) + 0.5 * std::exp(-x * x);
}

// A normal slope component of variance 1/2: y = erfinv(2u - 1), the root of
// erf(y) = v found by Newton steps kept inside a bisection bracket.  The
// bracket [-6, 6] holds every v the clamp allows (erf(6) = 1 - 2e-17).
double erfinv(double v) {
  v = std::clamp(v, -1.0 + 1e-16, 1.0 - 1e-16);
  double lo = -6.0;
  double hi = 6.0;
  double y = v * kSqrtPi / 2.0;
  for (int i = 0; i < 200; ++i) {
    const double f = std::erf(y) - v;
    if (f > 0.0) hi = y; else lo = y;
    const double df = 2.0 / kSqrtPi * std::exp(-y * y);
    double next = y - f / df;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - y) <= 1e-15 * std::max(1.0, std::abs(y)) || hi - lo <= 1e-15) return next;
    y = next;
  }
  return y;
}

}  // namespace

MicrofacetDistribution::MicrofacetDistribution(MicrofacetModel model, double alpha_x, double alpha_y)
    : model_(model), alpha_x_(alpha_x), alpha_y_(alpha_y) {
  // D divides by alpha_x alpha_y: a zero or non-finite roughness has no
  // distribution (a perfect mirror is a separate, delta, component).
  if (!(alpha_x > 0.0 && alpha_y > 0.0 && std::isfinite(alpha_x) && std::isfinite(alpha_y)))
    throw std::invalid_argument("MicrofacetDistribution: alpha_x and alpha_y must be finite and > 0");
}

double MicrofacetDistribution::D(const glm::dvec3& wm) const {
  if (wm.z <= 0.0) return 0.0;
  const double sx = wm.x / alpha_x_;
  const double sy = wm.y / alpha_y_;
  if (model_ == MicrofacetModel::ggx) {
    // Anisotropic GGX in Cartesian form (Heitz 2018, "Sampling the GGX
    // distribution of visible normals", eq. 1):
    //   D(wm) = 1 / (pi alpha_x alpha_y (x^2/alpha_x^2 + y^2/alpha_y^2 + z^2)^2)
    const double s = sx * sx + sy * sy + wm.z * wm.z;
    return 1.0 / (kPi * alpha_x_ * alpha_y_ * s * s);
  }
  // Anisotropic Beckmann (Heitz 2014, "Understanding the masking-shadowing
  // function in microfacet-based BRDFs", the anisotropic Beckmann NDF):
  //   D(wm) = exp(-tan^2(theta_m) (cos^2 phi/alpha_x^2 + sin^2 phi/alpha_y^2))
  //           / (pi alpha_x alpha_y cos^4(theta_m))
  const double z2 = wm.z * wm.z;
  const double e = std::exp(-(sx * sx + sy * sy) / z2);
  if (e == 0.0) return 0.0;  // also keeps 0/0 away when z^4 underflows
  return e / (kPi * alpha_x_ * alpha_y_ * z2 * z2);
}

double MicrofacetDistribution::lambda(const glm::dvec3& w) const {
  const double t2 = alpha2_tan2(w, alpha_x_, alpha_y_);
  if (std::isinf(t2)) return kInfinity;
  if (model_ == MicrofacetModel::ggx) {
    // GGX (Heitz 2014, the Smith Lambda of the GGX distribution):
    //   Lambda(w) = (-1 + sqrt(1 + alpha(phi)^2 tan^2(theta))) / 2,
    // in the cancellation-free form t2 / (2 (1 + sqrt(1 + t2))) near normal
    // incidence, where both terms of the difference are close to 1.
    if (t2 > 1.0) return 0.5 * (std::sqrt(1.0 + t2) - 1.0);
    return t2 / (2.0 * (1.0 + std::sqrt(1.0 + t2)));
  }
  // Beckmann (Heitz 2014, the Smith Lambda of the Beckmann distribution):
  //   Lambda(w) = (erf(a) - 1)/2 + exp(-a^2)/(2 a sqrt(pi)),
  //   a = 1 / (alpha(phi) tan(theta)).
  if (t2 == 0.0) return 0.0;
  return beckmann_lambda_of_a(1.0 / std::sqrt(t2));
}

// Smith's masking for the upper hemisphere (Heitz 2014, G1 = 1 / (1 + Lambda)).
double MicrofacetDistribution::g1(const glm::dvec3& w) const { return 1.0 / (1.0 + lambda(w)); }

double MicrofacetDistribution::facing_area_over_cos(const glm::dvec3& w) const {
  // Above: integral <w.wm>+ D dwm = cos(theta) (1 + Lambda(w)).  Below: the
  // normals facing w are those facing away from -w, whose area is the
  // back-facing part cos(theta') Lambda(-w) (Heitz 2014, the projected-area
  // identity split into front- and back-facing microfacets).
  const double l = lambda(w);  // even in w.z
  return w.z > 0.0 ? 1.0 + l : l;
}

double MicrofacetDistribution::visible_normal_pdf(const glm::dvec3& wo, const glm::dvec3& wm) const {
  const double cos_om = glm::dot(wo, wm);
  if (cos_om <= 0.0 || wm.z <= 0.0) return 0.0;
  // The distribution of visible normals (Heitz 2018, eq. 3):
  //   D_wo(wm) = G1(wo) <wo . wm>+ D(wm) / |wo . z|,
  // with G1 the full-sphere distant masking (supplement of Wang et al. 2022,
  // eq. 3), which normalises it for wo below the macro surface too.
  const double area = facing_area_over_cos(wo) * std::abs(wo.z);
  if (!(area > 0.0) || std::isinf(area)) return 0.0;
  return cos_om * D(wm) / area;
}

glm::dvec3 MicrofacetDistribution::sample_visible_normal(const glm::dvec3& wo, const glm::dvec2& u) const {
  return model_ == MicrofacetModel::ggx ? sample_visible_normal_ggx(wo, u)
                                        : sample_visible_normal_beckmann(wo, u);
}

glm::dvec3 MicrofacetDistribution::sample_visible_normal_ggx(const glm::dvec3& wo, const glm::dvec2& u) const {
  // Stretch to the alpha = 1 configuration, a hemisphere (Heitz 2018, §3).
  const glm::dvec3 wh = glm::normalize(glm::dvec3(alpha_x_ * wo.x, alpha_y_ * wo.y, wo.z));
  // The visible normals of the unit hemisphere seen from wh are the halfway
  // vectors between wh and directions c uniform on the spherical cap
  // c.z > -wh.z (Dupuy & Benyoub 2023, "Sampling visible GGX normals with
  // spherical caps", §3).  c uniform on the whole sphere would give the
  // visible normals of the whole sphere, density (wh . h) / pi; the cap keeps
  // exactly those with h.z > 0, so the construction holds for wh below the
  // macro surface as well.
  const double phi = 2.0 * kPi * u.y;
  const double z = (1.0 - u.x) * (1.0 + wh.z) - wh.z;  // uniform in (-wh.z, 1]
  const double sin_theta = std::sqrt(std::clamp(1.0 - z * z, 0.0, 1.0));
  const glm::dvec3 c(sin_theta * std::cos(phi), sin_theta * std::sin(phi), z);
  const glm::dvec3 h = c + wh;
  // Unstretch the normal: normals transform with the inverse transpose
  // (Heitz 2018, §3, the last step of its listing).
  const glm::dvec3 wm(alpha_x_ * h.x, alpha_y_ * h.y, std::max(h.z, 0.0));
  const double len = glm::length(wm);
  if (!(len > 0.0)) return glm::dvec3(0.0, 0.0, 1.0);
  return wm / len;
}

glm::dvec3 MicrofacetDistribution::sample_visible_normal_beckmann(const glm::dvec3& wo,
                                                                  const glm::dvec2& u) const {
  // Stretch to alpha = 1 (Heitz & d'Eon 2014: the visible slopes of a
  // stretched surface are the stretched visible slopes), then rotate the
  // azimuth of the view to the x axis so that the slope density separates:
  // x ~ (a - x)+ exp(-x^2), y ~ exp(-y^2), a = cot(theta).
  glm::dvec3 ws(alpha_x_ * wo.x, alpha_y_ * wo.y, wo.z);
  ws = glm::normalize(ws);
  const double sin_theta = std::sqrt(ws.x * ws.x + ws.y * ws.y);
  double cos_phi = 1.0;
  double sin_phi = 0.0;
  if (sin_theta > 0.0) {
    cos_phi = ws.x / sin_theta;
    sin_phi = ws.y / sin_theta;
  }

  double slope_x;
  if (sin_theta == 0.0 || std::abs(ws.z / sin_theta) > 26.0) {
    // At (near) normal incidence from above the truncation is beyond
    // double precision: the slope is plain Gaussian.  From (near) straight
    // below, only slopes steeper than 26 face wo and their density
    // underflows: the steepest representable slope stands in for them.
    slope_x = ws.z > 0.0 ? erfinv(2.0 * u.x - 1.0) : -26.0;
  } else {
    const double a = ws.z / sin_theta;
    const double total = beckmann_slope_cdf(a, a);
    const double target = u.x * total;
    // Invert F(x) = target on (-inf, a]: F is increasing with F' = (a - x)
    // exp(-x^2).  Bisection bracketed on [lo, a] with Newton steps when they
    // stay inside the bracket.
    double lo = std::min(a, 0.0) - 1.0;
    while (beckmann_slope_cdf(lo, a) > target && lo > -40.0) lo = 2.0 * lo;
    double hi = a;
    double x = 0.5 * (lo + hi);
    for (int i = 0; i < 200; ++i) {
      const double f = beckmann_slope_cdf(x, a) - target;
      if (f > 0.0) hi = x; else lo = x;
      const double df = (a - x) * std::exp(-x * x);
      double next = df > 0.0 ? x - f / df : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - x) <= 1e-14 * std::max(1.0, std::abs(x)) || hi - lo <= 1e-15) {
        x = next;
        break;
      }
      x = next;
    }
    slope_x = x;
  }
  const double slope_y = erfinv(2.0 * u.y - 1.0);

  // Rotate back, unstretch, and turn the slope into a normal (-sx, -sy, 1).
  const double sx = (cos_phi * slope_x - sin_phi * slope_y) * alpha_x_;
  const double sy = (sin_phi * slope_x + cos_phi * slope_y) * alpha_y_;
  return glm::normalize(glm::dvec3(-sx, -sy, 1.0));
}

}  // namespace skyfarm::material

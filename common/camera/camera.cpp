// The camera: pixels -> primary rays, and back (see camera.h for the
// parameters and conventions).
#include "common/camera/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>
#include <utility>

#include "common/core/constants.h"
#include "common/core/math.h"

namespace skyfarm {
namespace {

// sin(t) / t, with its Taylor series 1 - t^2/6 where the quotient would lose
// precision (the next term t^4/120 is below 1e-18 for |t| < 1e-4).
double sinc(double t) {
  if (std::abs(t) < 1e-4) return 1.0 - t * t / 6.0;
  return std::sin(t) / t;
}

// Solid angle of the rectangle [0, a] x [0, b] on the plane at unit distance,
// seen from the origin on the normal through its corner (0, 0):
//   F(a, b) = atan(a b / sqrt(1 + a^2 + b^2)),
// the antiderivative of the pinhole Jacobian (1 + a^2 + b^2)^(-3/2) in a and b
// (R. J. Mathar, "Solid angle of a rectangular plate", 2014; its four-corner
// sum is the pyramid formula 4 asin(sin a sin b), Wikipedia "Solid angle").
// Signed in a and b, so a rectangle [a0, a1] x [b0, b1] subtends
//   F(a1, b1) - F(a0, b1) - F(a1, b0) + F(a0, b0).
double rectangle_corner_solid_angle(double a, double b) { return std::atan(a * b / std::sqrt(1.0 + a * a + b * b)); }

// Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun 25.4.30),
// the positive half; the rule is symmetric.
constexpr std::array<double, 2> kGl4X = {0.3399810435848562648, 0.8611363115940525752};
constexpr std::array<double, 2> kGl4W = {0.6521451548625461427, 0.3478548451374538573};
constexpr std::array<double, 4> kGl8X = {0.1834346424956498049, 0.5255324099163289858, 0.7966664774136267396,
                                         0.9602898564975362317};
constexpr std::array<double, 4> kGl8W = {0.3626837833783619830, 0.3137066458778872873, 0.2223810344533744706,
                                         0.1012285362903762591};

// Integral of f over [lo, hi] by a symmetric Gauss-Legendre rule.
template <std::size_t N, typename F>
double gauss_legendre(const std::array<double, N>& x, const std::array<double, N>& w, double lo, double hi, F&& f) {
  const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  double sum = 0.0;
  for (std::size_t i = 0; i < N; ++i) sum += w[i] * (f(mid - half * x[i]) + f(mid + half * x[i]));
  return half * sum;
}

}  // namespace

Camera::Camera(const CameraSpec& spec, const glm::dvec3& position)
    : projection_(spec.projection), width_(spec.width), height_(spec.height), position_(position) {
  if (spec.width < 1 || spec.height < 1) throw std::invalid_argument("camera: width and height must be at least 1");
  if (!std::isfinite(spec.yaw_deg) || !std::isfinite(spec.pitch_deg) || !std::isfinite(spec.roll_deg))
    throw std::invalid_argument("camera: yaw_deg, pitch_deg and roll_deg must be finite");
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z))
    throw std::invalid_argument("camera: position must be finite");
  const double fov = spec.fov_deg;
  if (projection_ == Projection::kPerspective && !(fov > 0.0 && fov < 180.0))
    throw std::invalid_argument("camera: perspective fov_deg must be in (0, 180)");
  if (projection_ == Projection::kFisheye && !(fov > 0.0 && fov <= 360.0))
    throw std::invalid_argument("camera: fisheye fov_deg must be in (0, 360]");

  // Level frame at azimuth yaw (clockwise from north: direction (sin a, cos a, 0)).
  const double yaw = spec.yaw_deg * kDegToRad;
  const double sy = std::sin(yaw), cy = std::cos(yaw);
  const glm::dvec3 f0(sy, cy, 0.0), r0(cy, -sy, 0.0), u0(0.0, 0.0, 1.0);
  // Pitch: rotate f0 and u0 about r0 by p (positive p raises f towards u0).
  const double p = spec.pitch_deg * kDegToRad;
  const double sp = std::sin(p), cp = std::cos(p);
  const glm::dvec3 f = cp * f0 + sp * u0, u = -sp * f0 + cp * u0;
  // Roll: a right-handed rotation by q about f (Rodrigues with f x r = -u,
  // f x u = r), i.e. clockwise as seen from behind the camera.
  const double q = spec.roll_deg * kDegToRad;
  const double sq = std::sin(q), cq = std::cos(q);
  forward_ = glm::normalize(f);
  right_ = glm::normalize(cq * r0 - sq * u);
  up_ = glm::normalize(sq * r0 + cq * u);

  const double w = width_, h = height_;
  switch (projection_) {
    case Projection::kPerspective:
      tan_half_x_ = std::tan(0.5 * fov * kDegToRad);
      tan_half_y_ = tan_half_x_ * h / w;
      break;
    case Projection::kFisheye:
      centre_x_ = 0.5 * w;
      centre_y_ = 0.5 * h;
      radius_px_ = 0.5 * std::min(w, h);
      half_fov_ = 0.5 * fov * kDegToRad;
      break;
    case Projection::kEquirectangular:
      break;
  }
}

bool Camera::pixel_exists(int x, int y) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return false;
  if (projection_ != Projection::kFisheye) return true;
  // Normalised film coordinates of the pixel centre, y up.
  const double a = (x + 0.5 - centre_x_) / radius_px_;
  const double b = (centre_y_ - (y + 0.5)) / radius_px_;
  return a * a + b * b <= 1.0;
}

bool Camera::generate_ray(int x, int y, double jx, double jy, Ray* ray) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return false;
  glm::dvec3 d;
  if (!film_to_direction(x + jx, y + jy, &d)) return false;
  ray->o = position_;
  ray->d = d;
  return true;
}

// Film point (fx, fy) -> unit direction, per projection (formulas in camera.h).
//
// Equirect: polar angle from up alpha = pi v (so the poles are exact: alpha = 0
// gives d = up with no 0 * inf), relative azimuth phi = 2 pi (u - 1/2):
//   d = sin(alpha) (cos(phi) f + sin(phi) r) + cos(alpha) u.
// Fisheye (equidistant, Kannala & Brandt 2006 "r = f theta"): a, b the
// normalised film coordinates (y up), rho = |(a, b)|, theta = k rho with
// k = fov / 2; sin(theta) (cos psi, sin psi) = sin(theta) (a, b) / rho
// = k sinc(theta) (a, b), finite at the centre.
// Perspective: the pinhole of camera.h.
bool Camera::film_to_direction(double fx, double fy, glm::dvec3* d) const {
  const double w = width_, h = height_;
  switch (projection_) {
    case Projection::kEquirectangular: {
      const double phi = 2.0 * kPi * (fx / w - 0.5);
      const double alpha = kPi * (fy / h);
      const double s = std::sin(alpha);
      *d = s * (std::cos(phi) * forward_ + std::sin(phi) * right_) + std::cos(alpha) * up_;
      break;
    }
    case Projection::kFisheye: {
      const double a = (fx - centre_x_) / radius_px_;
      const double b = (centre_y_ - fy) / radius_px_;
      const double rho2 = a * a + b * b;
      if (rho2 > 1.0) return false;
      const double theta = half_fov_ * std::sqrt(rho2);
      const double s = half_fov_ * sinc(theta);
      *d = std::cos(theta) * forward_ + s * (a * right_ + b * up_);
      break;
    }
    case Projection::kPerspective: {
      const double x_ndc = 2.0 * fx / w - 1.0;
      const double y_ndc = 1.0 - 2.0 * fy / h;
      *d = forward_ + (x_ndc * tan_half_x_) * right_ + (y_ndc * tan_half_y_) * up_;
      break;
    }
  }
  *d = glm::normalize(*d);
  return true;
}

// The inverses of film_to_direction, from the camera-frame components
// (l_f, l_r, l_u) = (d.f, d.r, d.u).  Angles by atan2 of a sine and a cosine,
// accurate everywhere (acos loses half the digits near the axis).
bool Camera::direction_to_film(const glm::dvec3& d, double* fx, double* fy) const {
  const double lf = glm::dot(d, forward_), lr = glm::dot(d, right_), lu = glm::dot(d, up_);
  const double w = width_, h = height_;
  switch (projection_) {
    case Projection::kEquirectangular: {
      const double phi = std::atan2(lr, lf);  // [-pi, pi]
      const double alpha = std::atan2(std::hypot(lf, lr), lu);
      double x = (phi / (2.0 * kPi) + 0.5) * w;
      if (x >= w) x -= w;  // phi = +pi: the seam, column 0
      *fx = std::max(x, 0.0);
      *fy = alpha / kPi * h;
      return true;
    }
    case Projection::kFisheye: {
      const double s = std::hypot(lr, lu);
      const double theta = std::atan2(s, lf);
      // A relative 1e-12 of slack so that a direction made from a point on
      // the circle maps back onto it.
      if (theta > half_fov_ * (1.0 + 1e-12)) return false;
      const double rho = std::min(theta / half_fov_, 1.0);
      const double a = s > 0.0 ? rho * lr / s : 0.0;
      const double b = s > 0.0 ? rho * lu / s : 0.0;
      *fx = centre_x_ + radius_px_ * a;
      *fy = centre_y_ - radius_px_ * b;
      return true;
    }
    case Projection::kPerspective: {
      if (!(lf > 0.0)) return false;
      const double x = 0.5 * (lr / (lf * tan_half_x_) + 1.0) * w;
      const double y = 0.5 * (1.0 - lu / (lf * tan_half_y_)) * h;
      if (!(x >= 0.0 && x <= w && y >= 0.0 && y <= h)) return false;
      *fx = x;
      *fy = y;
      return true;
    }
  }
  return false;
}

// Equirect: the pixel is a latitude-longitude cell; with phi the azimuth and
// e the elevation, dOmega = cos(e) de dphi, so
//   Omega = dphi (sin e_top - sin e_bottom) = (2 pi / W) 2 sin(pi (y + 1/2) / H) sin(pi / (2 H))
// (sum-to-product: sin A - sin B = 2 cos((A+B)/2) sin((A-B)/2), and
// cos(e_mid) = sin(polar angle of the row centre)); the rows telescope to 4 pi.
// Perspective: the pixel's rectangle on the plane at unit distance, by the
// signed corner formula above (exact).
double Camera::pixel_solid_angle(int x, int y) const {
  if (!pixel_exists(x, y)) return 0.0;
  const double w = width_, h = height_;
  switch (projection_) {
    case Projection::kEquirectangular:
      return (2.0 * kPi / w) * 2.0 * std::sin(kPi * (y + 0.5) / h) * std::sin(0.5 * kPi / h);
    case Projection::kPerspective: {
      const double a0 = (2.0 * x / w - 1.0) * tan_half_x_, a1 = (2.0 * (x + 1) / w - 1.0) * tan_half_x_;
      const double b0 = (1.0 - 2.0 * (y + 1) / h) * tan_half_y_, b1 = (1.0 - 2.0 * y / h) * tan_half_y_;
      return rectangle_corner_solid_angle(a1, b1) - rectangle_corner_solid_angle(a0, b1) -
             rectangle_corner_solid_angle(a1, b0) + rectangle_corner_solid_angle(a0, b0);
    }
    case Projection::kFisheye:
      return fisheye_pixel_solid_angle(x, y);
  }
  return 0.0;
}

// Equidistant fisheye: theta = k rho on the normalised film (a, b), so
//   dOmega = sin(theta) dtheta dpsi = k sin(k rho) drho dpsi = k^2 sinc(k rho) da db
// (film area rho drho dpsi).  The Jacobian k^2 sinc(k rho) is analytic in
// (a, b) (sinc is even), so over a pixel wholly inside the circle a 4 x 4
// Gauss-Legendre rule suffices (degree 7 on a cell of side 1/R; remainder
// ~5e-10 (k/R)^8 relative: < 1e-14 for R >= 10 px, ~1e-9 at R = 2 px).  A
// pixel the circle crosses is integrated over its part inside the circle:
// outer 8-point rule in a, split where the circle crosses the pixel's top or
// bottom edge (so the inner limits max(b0, -c), min(b1, c), c = sqrt(1 - a^2),
// are smooth on each piece), inner 4-point rule in b.  Only the two pixels
// holding the circle's leftmost and rightmost points (a = +-1, where the
// chord's length goes like a square root) keep a singular endpoint (~6e-6 of a
// pixel's solid angle there; ~1e-13 elsewhere, checked against the exact area
// of a square clipped by the circle in the tests).  Integrating over all
// pixels gives 2 pi (1 - cos k); the pixels that do not exist (centre
// outside) are left out, so the sum over existing pixels falls short by their
// slivers inside the circle (0.2 % of the cap for R = 100 px, fov 180).
double Camera::fisheye_pixel_solid_angle(int x, int y) const {
  const double k = half_fov_, inv_r = 1.0 / radius_px_;
  const double a0 = (x - centre_x_) * inv_r, a1 = (x + 1 - centre_x_) * inv_r;
  const double b0 = (centre_y_ - (y + 1)) * inv_r, b1 = (centre_y_ - y) * inv_r;
  auto jacobian = [k](double a, double b) { return k * k * sinc(k * std::sqrt(a * a + b * b)); };

  const double far_a = std::max(std::abs(a0), std::abs(a1)), far_b = std::max(std::abs(b0), std::abs(b1));
  if (far_a * far_a + far_b * far_b <= 1.0) {
    return gauss_legendre(kGl4X, kGl4W, a0, a1, [&](double a) {
      return gauss_legendre(kGl4X, kGl4W, b0, b1, [&](double b) { return jacobian(a, b); });
    });
  }

  const double lo = std::max(a0, -1.0), hi = std::min(a1, 1.0);
  if (!(hi > lo)) return 0.0;
  std::array<double, 6> breaks{};
  std::size_t n = 0;
  breaks[n++] = lo;
  for (double b : {b0, b1}) {
    if (std::abs(b) >= 1.0) continue;
    const double c = std::sqrt((1.0 - b) * (1.0 + b));
    for (double a : {-c, c})
      if (a > lo && a < hi) breaks[n++] = a;
  }
  breaks[n++] = hi;
  // Insertion sort of at most 6 values (std::sort trips GCC 12's -Warray-bounds here).
  for (std::size_t i = 1; i < n; ++i)
    for (std::size_t j = i; j > 0 && breaks[j] < breaks[j - 1]; --j) std::swap(breaks[j], breaks[j - 1]);

  auto column = [&](double a) {
    const double c = safe_sqrt((1.0 - a) * (1.0 + a));
    const double bl = std::max(b0, -c), bh = std::min(b1, c);
    if (!(bh > bl)) return 0.0;
    return gauss_legendre(kGl4X, kGl4W, bl, bh, [&](double b) { return jacobian(a, b); });
  };
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i)
    if (breaks[i + 1] > breaks[i]) sum += gauss_legendre(kGl8X, kGl8W, breaks[i], breaks[i + 1], column);
  return sum;
}

}  // namespace skyfarm

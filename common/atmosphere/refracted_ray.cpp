#include "common/atmosphere/refracted_ray.h"

#include <algorithm>
#include <cmath>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

// A(s) = atan2(sqrt(s^2 - k^2), k) = 90 deg - z where n r = s, with s^2 - k^2
// as (s - k)(s + k) so that grazing rays keep their precision.  In vacuum
// (s = r) it is the polar angle of a straight line of impact parameter k,
// measured from its tangent point.
double turning_angle(double k, double s) {
  return std::atan2(std::sqrt(std::max(0.0, (s - k) * (s + k))), k);
}

// Polar angle swept inside a shell of exponent beta between radii r_a and r_b
// (r monotone in between) where n r is s_a and s_b, A_a = A(s_a) and
// A_b = A(s_b) (each boundary's A serves both shells it bounds: one atan2
// per step, not two).
double sweep(double k, double beta, double r_a, double s_a, double A_a, double r_b, double s_b, double A_b) {
  if (std::abs(beta) > 1e-9) return std::abs(A_b - A_a) / std::abs(beta);
  // n r constant: the ray keeps its zenith angle; dphi = tan z dr / r.
  const double s = 0.5 * (s_a + s_b);
  return k / std::sqrt(std::max(1e-300, (s - k) * (s + k))) * std::abs(std::log(r_b / r_a));
}

}  // namespace

RefractedRay trace_refracted_ray(const RefractiveShells& shells, double observer_radius_m, double zenith_deg,
                                 bool record_path) {
  RefractedRay out;
  trace_refracted_ray(shells, observer_radius_m, zenith_deg, record_path, &out);
  return out;
}

void trace_refracted_ray(const RefractiveShells& shells, double observer_radius_m, double zenith_deg,
                         bool record_path, RefractedRay* result) {
  RefractedRay& out = *result;
  out.path.clear();
  out = RefractedRay{RefractedRay::Outcome::kEscaped, std::move(out.path)};
  const double z0 = std::clamp(zenith_deg, 0.0, 180.0) * kDegToRad;
  const double top = shells.top_radius_m();
  double r = std::max(observer_radius_m, shells.ground_radius_m());
  double phi = 0.0;
  bool up = z0 <= 0.5 * kPi;
  auto record = [&] {
    if (record_path) out.path.push_back({r, phi});
  };
  record();
  out.lowest_radius_m = r;

  int shell;
  double k, s;
  if (r >= top) {
    // Above the atmosphere: straight until the top sphere, if it is met.
    k = r * std::sin(z0);
    out.invariant_m = k;
    if (up || k >= top) {
      out.lowest_radius_m = up ? r : k;
      out.exit_direction_rad = z0;
      return;
    }
    phi = turning_angle(k, r) - turning_angle(k, top);
    r = s = top;
    record();
    shell = shells.shell_count() - 1;
  } else {
    shell = shells.shell_at(r);
    s = shells.index_at(shell, r) * r;
    k = s * std::sin(z0);
  }
  out.invariant_m = k;

  // Each step goes to the next boundary, or to the turning point (s = k) inside
  // the shell when the boundary lies where the ray cannot go (s_b < k).
  const long max_steps = 4L * shells.shell_count() + 16;
  bool escaped = false;
  double A = turning_angle(k, s);  // A(s) where the ray is
  for (long step = 0; step < max_steps; ++step) {
    const double beta = shells.beta(shell);
    const int boundary = up ? shell + 1 : shell;
    const double r_b = shells.radius_m(boundary);
    const double s_b = shells.index(boundary) * r_b;
    if (s_b >= k) {
      const double A_b = turning_angle(k, s_b);
      phi += sweep(k, beta, r, s, A, r_b, s_b, A_b);
      r = r_b;
      s = s_b;
      A = A_b;
      record();
      if (up && shell + 1 == shells.shell_count()) {
        escaped = true;
        break;
      }
      if (!up && shell == 0) {
        out.lowest_radius_m = r;
        out.outcome = RefractedRay::Outcome::kHitGround;
        return;
      }
      shell += up ? 1 : -1;
    } else {
      // s = k at r_t = r_i (k / s_i)^(1 / beta) (beta != 0 here: s varies in the shell).
      const double r_i = shells.radius_m(shell);
      const double s_i = shells.index(shell) * r_i;
      const double r_t = r_i * std::exp(std::log(k / s_i) / beta);
      phi += sweep(k, beta, r, s, A, r_t, k, 0.0);
      r = r_t;
      s = k;
      A = 0.0;
      record();
      if (!up) out.lowest_radius_m = std::min(out.lowest_radius_m, r);
      up = !up;
    }
    if (phi > 2.0 * kPi) break;
  }
  if (!escaped) {
    out.outcome = RefractedRay::Outcome::kTrapped;
    return;
  }
  // Out through the top into vacuum: n = 1 there, sin z = k / r_top, going up.
  out.exit_direction_rad = phi + std::atan2(k, std::sqrt(std::max(0.0, (top - k) * (top + k))));
  out.bending_rad = out.exit_direction_rad - z0;
}

glm::dvec3 path_point(const RayVertex& vertex, const glm::dvec3& up, const glm::dvec3& forward) {
  return vertex.radius_m * plane_direction(vertex.polar_angle_rad, up, forward);
}

glm::dvec3 plane_direction(double psi_rad, const glm::dvec3& up, const glm::dvec3& forward) {
  return std::cos(psi_rad) * up + std::sin(psi_rad) * forward;
}

}  // namespace skyfarm

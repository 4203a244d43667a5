// Walks a ray through the concentric altitude shells of a MajorantGrid,
// yielding the segments [t0, t1] of the ray that lie in each shell, in order.
//
// Shell k spans radii [rho_k, rho_{k+1}], rho_k = R + h_k.  Along the ray the
// distance to the centre first falls (until the closest approach at
// t* = -o.d) and then rises, so the ray crosses shells inward while t < t*,
// through the bottom sphere of its shell (the near root of that sphere), and
// outward afterwards, through the top sphere (the far root).  Every crossing
// comes from intersect_sphere (stable quadratic, sphere_intersection.h) with
// the ray's own origin, so no error accumulates along long rays from orbit.
// Whether a ray turns around inside a shell is decided by its closest approach
// l < rho_k alone, the same test that decides ground hits.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include "common/geometry/ray.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

struct ShellSegment {
  double t0 = 0.0, t1 = 0.0;
  std::size_t shell = 0;
};

class ShellTraversal {
 public:
  // A walk of nothing (next() is false at once).
  ShellTraversal() : done_(true) {}
  // shell_bottoms: the altitudes h_0 = 0 < h_1 < ... < h_K = top (K + 1 values).
  // The walk covers [t_begin, t_end] of the ray; the caller makes t_begin a
  // point inside the atmosphere (or its entry point) and t_end the ground hit,
  // the exit from the top, or any nearer distance.
  ShellTraversal(const Ray& ray, double planet_radius_m, std::span<const double> shell_bottoms, double t_begin,
                 double t_end);
  // The same walk with the ray's radial constants already at hand (radial_ray(ray)).
  ShellTraversal(const Ray& ray, const RadialRay& radial, double planet_radius_m, std::span<const double> shell_bottoms,
                 double t_begin, double t_end);

  // The next segment; false when the walk is over.
  bool next(ShellSegment* segment);

 private:
  double radius(std::size_t k) const { return R_ + h_[k]; }
  // Roots of |o + t d| = rho from the cached ray constants (see
  // sphere_intersection.h for the stable forms); false when the line misses.
  bool roots(double rho, double* t_near, double* t_far) const;

  Ray ray_;
  double R_ = 0.0;
  std::span<const double> h_;
  double t_ = 0.0, t_end_ = 0.0, t_turn_ = 0.0;
  double r0_ = 0.0, b_ = 0.0, l_ = 0.0;  // |o|, o.d, closest approach of the line to the centre
  std::size_t shell_ = 0;
  bool inbound_ = false;
  bool done_ = false;
};

// Inline: the walk's state stays in registers in the callers' loops
// (free_flight.h), one call per shell crossed.
inline bool ShellTraversal::roots(double rho, double* t_near, double* t_far) const {
  const double D = (rho - l_) * (rho + l_);
  if (D < 0.0) return false;
  const double c = (r0_ - rho) * (r0_ + rho);
  const double q = -(b_ + std::copysign(std::sqrt(D), b_));
  if (q == 0.0) {
    *t_near = *t_far = 0.0;
    return true;
  }
  const double t0 = q, t1 = c / q;
  *t_near = std::min(t0, t1);
  *t_far = std::max(t0, t1);
  return true;
}

inline bool ShellTraversal::next(ShellSegment* segment) {
  if (done_) return false;
  const std::size_t K = h_.size() - 1;
  double t_next = t_end_;
  std::size_t shell_after = shell_;
  bool inbound_after = inbound_;
  if (inbound_) {
    // Going down: through the bottom of this shell, unless the ray turns
    // around inside it (then on to its top, outbound).
    double near = 0.0, far = 0.0;
    if (roots(radius(shell_), &near, &far) && near >= t_) {
      t_next = near;
      if (shell_ == 0) {
        shell_after = K;  // the ground: nothing below
      } else {
        shell_after = shell_ - 1;
      }
    } else {
      t_next = roots(radius(shell_ + 1), &near, &far) ? far : t_end_;
      shell_after = shell_ + 1;
      inbound_after = false;
    }
  } else {
    double near = 0.0, far = 0.0;
    t_next = roots(radius(shell_ + 1), &near, &far) ? far : t_end_;
    shell_after = shell_ + 1;
  }
  t_next = std::max(t_next, t_);
  segment->t0 = t_;
  segment->t1 = std::min(t_next, t_end_);
  segment->shell = shell_;
  t_ = t_next;
  shell_ = shell_after;
  inbound_ = inbound_after;
  if (t_ >= t_end_ || shell_ >= K) done_ = true;
  return true;
}

}  // namespace skyfarm

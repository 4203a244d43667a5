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
  double R_;
  std::span<const double> h_;
  double t_, t_end_, t_turn_;
  double r0_, b_, l_;  // |o|, o.d, closest approach of the line to the centre
  std::size_t shell_;
  bool inbound_;
  bool done_ = false;
};

}  // namespace skyfarm

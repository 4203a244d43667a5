#include "common/render/shell_traversal.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

ShellTraversal::ShellTraversal(const Ray& ray, double planet_radius_m, std::span<const double> shell_bottoms,
                               double t_begin, double t_end)
    : ShellTraversal(ray, radial_ray(ray), planet_radius_m, shell_bottoms, t_begin, t_end) {}

ShellTraversal::ShellTraversal(const Ray& ray, const RadialRay& radial, double planet_radius_m,
                               std::span<const double> shell_bottoms, double t_begin, double t_end)
    : ray_(ray), R_(planet_radius_m), h_(shell_bottoms), t_(t_begin), t_end_(t_end) {
  r0_ = radial.r;
  b_ = radial.b;
  l_ = radial.l;
  t_turn_ = -b_;
  inbound_ = t_ < t_turn_;
  const std::size_t K = h_.size() - 1;
  // The shell of the starting point, by its altitude; a point on a boundary
  // belongs to the shell the ray is about to enter.  At t = 0 the point is
  // the origin (o + 0 d == o exactly), whose distance is r0.
  const double h = (t_ == 0.0 ? r0_ : glm::length(ray_.at(t_))) - R_;
  const auto it = std::upper_bound(h_.begin(), h_.end(), h);
  std::size_t k = static_cast<std::size_t>(it - h_.begin());
  k = (k == 0) ? 0 : k - 1;
  if (k >= K) k = K - 1;
  if (inbound_ && k > 0 && h <= h_[k]) --k;  // exactly on a bottom boundary going down
  shell_ = k;
  if (!(t_end_ > t_begin)) done_ = true;
}

bool ShellTraversal::roots(double rho, double* t_near, double* t_far) const {
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

bool ShellTraversal::next(ShellSegment* segment) {
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

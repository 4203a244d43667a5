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

}  // namespace skyfarm

#include "common/render/shell_traversal.h"

#include <algorithm>
#include <glm/geometric.hpp>

#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

ShellTraversal::ShellTraversal(const Ray& ray, double planet_radius_m, std::span<const double> shell_bottoms,
                               double t_begin, double t_end)
    : ray_(ray), R_(planet_radius_m), h_(shell_bottoms), t_(t_begin), t_end_(t_end) {
  t_turn_ = -glm::dot(ray_.o, ray_.d);
  inbound_ = t_ < t_turn_;
  const std::size_t K = h_.size() - 1;
  // The shell of the starting point, by its altitude; a point on a boundary
  // belongs to the shell the ray is about to enter.
  const double h = glm::length(ray_.at(t_)) - R_;
  const auto it = std::upper_bound(h_.begin(), h_.end(), h);
  std::size_t k = static_cast<std::size_t>(it - h_.begin());
  k = (k == 0) ? 0 : k - 1;
  if (k >= K) k = K - 1;
  if (inbound_ && k > 0 && h <= h_[k]) --k;  // exactly on a bottom boundary going down
  shell_ = k;
  if (!(t_end_ > t_begin)) done_ = true;
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
    const SphereHit bottom = intersect_sphere(ray_, radius(shell_));
    if (bottom.hit && bottom.t_near >= t_) {
      t_next = bottom.t_near;
      if (shell_ == 0) {
        shell_after = K;  // the ground: nothing below
      } else {
        shell_after = shell_ - 1;
      }
    } else {
      const SphereHit top = intersect_sphere(ray_, radius(shell_ + 1));
      t_next = top.hit ? top.t_far : t_end_;
      shell_after = shell_ + 1;
      inbound_after = false;
    }
  } else {
    const SphereHit top = intersect_sphere(ray_, radius(shell_ + 1));
    t_next = top.hit ? top.t_far : t_end_;
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

#include "common/clouds/uniform_cloud_slab.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "common/clouds/shell_intervals.h"

namespace skyfarm {

UniformCloudSlab::UniformCloudSlab(double planet_radius_m, double bottom_m, double top_m, double sigma_t,
                                   CloudOptics optics)
    : radius_(planet_radius_m), bottom_(bottom_m), top_(top_m), sigma_(sigma_t), optics_(std::move(optics)) {
  if (!(bottom_m >= 0.0 && top_m > bottom_m && std::isfinite(top_m)))
    throw std::invalid_argument("cloud slab: need 0 <= bottom < top, got " + std::to_string(bottom_m) + ", " +
                                std::to_string(top_m));
  if (!(sigma_t > 0.0 && std::isfinite(sigma_t)))
    throw std::invalid_argument("cloud slab: sigma_t must be > 0, got " + std::to_string(sigma_t));
}

double UniformCloudSlab::sigma_t(const glm::dvec3& p) const {
  const double h = glm::length(p) - radius_;
  return h >= bottom_ && h <= top_ ? sigma_ : 0.0;
}

void UniformCloudSlab::for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const {
  const ShellIntervals s = shell_intervals(ray, radius_ + bottom_, radius_ + top_, t_begin, t_end);
  for (int i = 0; i < s.count; ++i)
    if (!visit(s.t0[static_cast<std::size_t>(i)], s.t1[static_cast<std::size_t>(i)], sigma_)) return;
}

}  // namespace skyfarm

#include "common/atmosphere/atmosphere.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "common/core/integrate.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

Atmosphere::Atmosphere(double planet_radius_m, double top_altitude_m, std::vector<Constituent> constituents,
                       LambertianGround ground)
    : planet_radius_m_(planet_radius_m),
      top_altitude_m_(top_altitude_m),
      constituents_(std::move(constituents)),
      ground_(std::move(ground)) {
  if (!(planet_radius_m_ > 0.0) || !(top_altitude_m_ > 0.0))
    throw std::invalid_argument("atmosphere: planet radius and top altitude must be positive");
}

double Atmosphere::sigma_s(double h, double lambda_nm) const {
  if (h > top_altitude_m_) return 0.0;
  double s = 0.0;
  for (const auto& c : constituents_) s += c.sigma_s(h, lambda_nm);
  return s;
}

double Atmosphere::sigma_a(double h, double lambda_nm) const {
  if (h > top_altitude_m_) return 0.0;
  double s = 0.0;
  for (const auto& c : constituents_) s += c.sigma_a(h, lambda_nm);
  return s;
}

double Atmosphere::sigma_t(double h, double lambda_nm) const { return sigma_s(h, lambda_nm) + sigma_a(h, lambda_nm); }

double Atmosphere::vertical_optical_depth(double lambda_nm, double h0, double h1, int constituent) const {
  h0 = std::clamp(h0, 0.0, top_altitude_m_);
  h1 = std::clamp(h1, 0.0, top_altitude_m_);
  if (h1 < h0) std::swap(h0, h1);
  double tau = 0.0;
  for (std::size_t i = 0; i < constituents_.size(); ++i) {
    if (constituent >= 0 && static_cast<std::size_t>(constituent) != i) continue;
    const Constituent& c = constituents_[i];
    for (const SpectralCoefficient* k : {&c.k_scattering, &c.k_absorption}) {
      if (k->is_zero()) continue;
      if (k->altitude_independent()) {
        // tau = k(lambda) int rho dh
        tau += k->eval(lambda_nm, 0.0) * c.density.column(h0, h1);
      } else {
        tau += integrate_adaptive_simpson(
            [&](double h) { return c.density.eval(h) * k->eval(lambda_nm, h); }, h0, h1, 1e-9);
      }
    }
  }
  return tau;
}

double Atmosphere::optical_depth(const Ray& ray, double t_max, double lambda_nm) const {
  // Clip to the atmosphere shell and to the ground.
  const SphereHit top = intersect_sphere(ray, top_radius_m());
  if (!top.hit) return 0.0;
  double t0 = std::max(0.0, top.t_near);
  double t1 = std::min(t_max, top.t_far);
  const double t_ground = ground_distance(ray, planet_radius_m_);
  if (t_ground >= 0.0) t1 = std::min(t1, t_ground);
  if (t1 <= t0) return 0.0;
  auto sigma_t_at = [&](double t) { return sigma_t(altitude_above(ray.at(t), planet_radius_m_), lambda_nm); };
  // Split at the closest approach to the centre (where the altitude turns).
  const double t_min = -glm::dot(ray.o, ray.d);
  if (t_min > t0 && t_min < t1)
    return integrate_adaptive_simpson(sigma_t_at, t0, t_min, 1e-9) +
           integrate_adaptive_simpson(sigma_t_at, t_min, t1, 1e-9);
  return integrate_adaptive_simpson(sigma_t_at, t0, t1, 1e-9);
}

}  // namespace skyfarm

#include "common/render/sun_pixels.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {

namespace {

std::vector<std::uint32_t> pixels_near(const Camera& camera, const glm::dvec3& centre, double radius_rad) {
  std::vector<std::uint32_t> out;
  double fx = 0.0, fy = 0.0;
  if (!camera.direction_to_film(centre, &fx, &fy)) return out;
  const int cx = std::clamp(static_cast<int>(fx), 0, camera.width() - 1);
  const int cy = std::clamp(static_cast<int>(fy), 0, camera.height() - 1);
  // Angular size of a pixel near the sun, and the window that can reach the disk.
  const double pixel = std::sqrt(std::max(camera.pixel_solid_angle(cx, cy), 1e-30));
  const double reach = radius_rad + 2.0 * pixel;
  const int r = std::min(camera.width() + camera.height(), static_cast<int>(std::ceil(reach / pixel)) + 1);
  const double cos_reach = std::cos(std::min(reach, 3.14159));
  for (int y = std::max(0, cy - r); y <= std::min(camera.height() - 1, cy + r); ++y)
    for (int dx = -r; dx <= r; ++dx) {
      // Equirectangular maps wrap around in x.
      int x = cx + dx;
      if (camera.projection() == Projection::kEquirectangular) x = ((x % camera.width()) + camera.width()) % camera.width();
      if (x < 0 || x >= camera.width()) continue;
      Ray ray;
      if (!camera.pixel_exists(x, y) || !camera.generate_ray(x, y, 0.5, 0.5, &ray)) continue;
      if (glm::dot(ray.d, centre) >= cos_reach)
        out.push_back(static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(camera.width()) +
                      static_cast<std::uint32_t>(x));
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// The rims' dispersion near the horizon: < 0.6' between 380 and 780 nm.
constexpr double kDispersionMargin_rad = 0.02 * kDegToRad;

}  // namespace

std::vector<std::uint32_t> sun_pixels(const Camera& camera, const Sun& sun) {
  if (sun.is_point()) return {};
  return pixels_near(camera, sun.direction(), sun.angular_radius_rad());
}

std::vector<std::uint32_t> sun_pixels(const Camera& camera, const Sun& sun, const AtmosphereRefraction* refraction,
                                      const glm::dvec3& observer) {
  if (!refraction) return sun_pixels(camera, sun);
  if (sun.is_point()) return {};
  const auto apparent = refraction->apparent_direction(observer, sun.direction(), 550.0);
  if (!apparent) return {};
  return pixels_near(camera, apparent->direction, sun.angular_radius_rad() + kDispersionMargin_rad);
}

}  // namespace skyfarm

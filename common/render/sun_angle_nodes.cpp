#include "common/render/sun_angle_nodes.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {

namespace {

// Any unit vector perpendicular to unit v.
glm::dvec3 perpendicular(const glm::dvec3& v) {
  const glm::dvec3 a = std::abs(v.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
  return glm::normalize(a - glm::dot(a, v) * v);
}

}  // namespace

SunZenithWindow vertex_sun_zenith_window(const Scene& scene, double window_deg) {
  const double R = scene.atmosphere().planet_radius_m();
  const glm::dvec3 sun = scene.sun().direction();
  const glm::dvec3 up_observer = glm::normalize(scene.observer());
  const double zenith_observer = std::acos(std::clamp(glm::dot(up_observer, sun), -1.0, 1.0));
  const double horizon_angle = std::acos(std::clamp(R / glm::length(scene.observer()), -1.0, 1.0));
  const double window = window_deg * kDegToRad + horizon_angle;
  return {std::max(0.0, zenith_observer - window), std::min(kPi, zenith_observer + window)};
}

SunNodeFrame sun_node_frame(const glm::dvec3& sun, double theta_s) {
  const glm::dvec3 e1 = perpendicular(sun);
  SunNodeFrame f;
  f.up = std::cos(theta_s) * sun + std::sin(theta_s) * e1;
  f.towards_sun = std::sin(theta_s) * sun - std::cos(theta_s) * e1;  // horizontal at the node
  f.side = glm::cross(f.up, f.towards_sun);
  return f;
}

}  // namespace skyfarm

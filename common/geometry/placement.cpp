#include "common/geometry/placement.h"

#include <cmath>
#include <glm/mat4x4.hpp>
#include <stdexcept>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

// sin and cos of an angle in degrees, exact at multiples of 90 degrees.
void sincos_deg(double deg, double* s, double* c) {
  const double r = std::fmod(deg, 360.0);
  const double q = r / 90.0;
  if (q == std::floor(q)) {
    const int k = ((static_cast<int>(q) % 4) + 4) % 4;
    static constexpr double kS[4] = {0.0, 1.0, 0.0, -1.0}, kC[4] = {1.0, 0.0, -1.0, 0.0};
    *s = kS[k];
    *c = kC[k];
    return;
  }
  *s = std::sin(r * kDegToRad);
  *c = std::cos(r * kDegToRad);
}

}  // namespace

glm::dmat3 rotation_from_yaw_pitch_roll(double yaw_deg, double pitch_deg, double roll_deg) {
  double sy, cy, sp, cp, sr, cr;
  sincos_deg(yaw_deg, &sy, &cy);
  sincos_deg(pitch_deg, &sp, &cp);
  sincos_deg(roll_deg, &sr, &cr);
  // glm matrices are built from columns.
  // Rz(-yaw): clockwise about up; north (0,1,0) -> (sin y, cos y, 0).
  const glm::dmat3 rz(glm::dvec3(cy, -sy, 0.0), glm::dvec3(sy, cy, 0.0), glm::dvec3(0.0, 0.0, 1.0));
  // Rx(pitch): forward (0,1,0) -> (0, cos p, sin p).
  const glm::dmat3 rx(glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(0.0, cp, sp), glm::dvec3(0.0, -sp, cp));
  // Ry(roll): right (1,0,0) -> (cos r, 0, -sin r).
  const glm::dmat3 ry(glm::dvec3(cr, 0.0, -sr), glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(sr, 0.0, cr));
  return rz * rx * ry;
}

Transform transform_from_placement(const Placement& pl) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(pl.translate_m[i]) || !std::isfinite(pl.rotate_deg[i]))
      throw std::invalid_argument("placement: translate_m and rotate_deg must be finite");
    if (!std::isfinite(pl.scale[i]) || pl.scale[i] == 0.0)
      throw std::invalid_argument("placement: scale must be finite and non-zero");
  }
  const glm::dmat3 r = rotation_from_yaw_pitch_roll(pl.rotate_deg.x, pl.rotate_deg.y, pl.rotate_deg.z);
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * pl.scale[c], 0.0);
  m[3] = glm::dvec4(pl.translate_m, 1.0);
  return Transform(m);
}

}  // namespace skyfarm

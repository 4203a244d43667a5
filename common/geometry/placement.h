// An object's placement in the observer's local east-north-up frame
// (x east, y north, z up, metres), as a lighting artist sets it.
//
//   translate_m  [east, north, up], metres: where the object's origin goes
//   rotate_deg   [yaw, pitch, roll], degrees, aviation (Tait-Bryan) angles
//                of the object's axes (x right, y forward, z up):
//                  yaw    heading about up, clockwise from north seen from
//                         above, the azimuth convention of the sun and of
//                         direction_from_zenith_azimuth (ray.h);
//                  pitch  nose up about the object's right axis;
//                  roll   about the forward axis, positive lowers the right
//                         side (+x goes down, the top leans right)
//                applied roll first, then pitch, then yaw:
//                  R = Rz(-yaw) Rx(pitch) Ry(roll)
//                so the object's forward axis +y ends up pointing along
//                direction_from_zenith_azimuth(90 - pitch, yaw).
//   scale        [sx, sy, sz] along the object's own axes, applied before
//                rotating; a request's single number s means [s, s, s].
//                Non-zero and finite; a negative factor mirrors the object.
//
// object -> local ENU:  p_enu = translate + R (scale * p_object)
//
// Worked example: a 2 m x 1 m panel (the unit rectangle, z = 0 plane, normal
// +z) standing upright facing south-east, its centre 10 m north at 1 m up:
//   scale [2, 1, 1]              2 m wide along x, 1 m tall along y
//   rotate_deg [-45, 90, 0]      pitch 90 tips the panel up: object +y
//                                (its top edge direction) -> ENU up, its
//                                normal +z -> south (azimuth 180); yaw -45
//                                turns it counter-clockwise to azimuth 135
//                                (south-east), its width along azimuth 45
//   translate_m [0, 10, 1]
// Multiples of 90 degrees give exact matrices (no 6e-17 residues).
#pragma once
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "common/geometry/transform.h"

namespace skyfarm {

struct Placement {
  glm::dvec3 translate_m{0.0};
  glm::dvec3 rotate_deg{0.0};  // yaw, pitch, roll
  glm::dvec3 scale{1.0};
};

// R = Rz(-yaw) Rx(pitch) Ry(roll), degrees.
glm::dmat3 rotation_from_yaw_pitch_roll(double yaw_deg, double pitch_deg, double roll_deg);

// object -> local ENU.  Throws std::invalid_argument for a zero or
// non-finite scale, or non-finite angles or translation.
Transform transform_from_placement(const Placement& placement);

}  // namespace skyfarm

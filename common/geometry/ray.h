// A ray in planet-centred coordinates, metres, double precision.
//
// Frame (used everywhere in skyfarm): origin at the planet's centre; +z
// through the observer's location (local up), +y towards local north, +x
// towards local east.  Directions are given as zenith angle from +z and
// azimuth clockwise from north (+y) towards east (+x), like the sun's.
#pragma once
#include <glm/vec3.hpp>

namespace skyfarm {

struct Ray {
  glm::dvec3 o;  // origin, m
  glm::dvec3 d;  // unit direction
  glm::dvec3 at(double t) const { return o + t * d; }
};

// Unit direction for a zenith angle and an azimuth (clockwise from north), radians:
// (sin z sin a, sin z cos a, cos z).
glm::dvec3 direction_from_zenith_azimuth(double zenith_rad, double azimuth_rad);
// The inverse, azimuth in [0, 2 pi).
void zenith_azimuth_from_direction(const glm::dvec3& d, double* zenith_rad, double* azimuth_rad);

}  // namespace skyfarm

// The equal-area octahedral mapping of the unit sphere onto the unit square
// (Clarberg 2008, "Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD",
// JGT 13(3)), the layout of pbrt-v4's `imagemap` infinite light.
//
//   square (s, t) in [0, 1]^2   s to the right, t DOWN (the image's rows:
//                               pixel (x, y) of an N x N image covers
//                               [x, x+1]/N x [y, y+1]/N)
//   sphere d = (x, y, z)        the centre (1/2, 1/2) is +z, the four corners
//                               are -z, the inscribed diamond |u| + |v| = 1
//                               (u = 2s - 1, v = 2t - 1) is the equator z = 0;
//                               u > 0 is x > 0, v > 0 is y > 0
//
// Equal area: every region of the square maps to a solid angle of 4 pi times
// its area, so each pixel of an N x N map holds 4 pi / N^2 sr.
//
// The env maps (server/sky) read d in the observer frame (x east, y north,
// z zenith), which is pbrt-v4's light frame for such a map: the zenith is
// the image centre, north is straight below it, east to its right.
#pragma once
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace skyfarm {

// A unit vector for a point of the square; p outside [0, 1]^2 is clamped.
glm::dvec3 equal_area_square_to_sphere(const glm::dvec2& p);

// The point of the square of a direction (need not be normalised; not zero).
// equal_area_square_to_sphere(equal_area_sphere_to_square(d)) == normalize(d)
// to a few ulps (the exact atan2, not Clarberg's polynomial).
glm::dvec2 equal_area_sphere_to_square(const glm::dvec3& d);

// Solid angle of one pixel of an N x N map, sr: 4 pi / N^2.
double equal_area_pixel_solid_angle(int n);

}  // namespace skyfarm

// Where a ray meets a shape, in the frame of the ray it was asked with.
//
//   t          distance along the ray in units of its direction's length
//              (rays carried to an object's frame keep their unnormalised
//              direction so t is the same number in every frame)
//   p          the hit point, reprojected onto the surface where the shape
//              allows it (sphere: |p| = 1; planes: the plane's coordinate
//              set exactly)
//   p_error    an absolute bound on each component of p's rounding error;
//              spawn.h offsets new rays by it so they start on the correct
//              side of the surface
//   n          unit geometric normal, outward for closed shapes, the +z side
//              for disc and rectangle, the counter-clockwise (front) side of
//              a triangle; never flipped to face the ray
//   uv         surface coordinates (each shape's header says which); for a
//              triangle the barycentrics (b1, b2) of vertices 1 and 2
//   primitive  the triangle's index in its mesh, the box's face (0..5:
//              -x, +x, -y, +y, -z, +z), 0 otherwise
#pragma once
#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace skyfarm {

struct ShapeHit {
  double t = 0.0;
  glm::dvec3 p{0.0};
  glm::dvec3 p_error{0.0};
  glm::dvec3 n{0.0, 0.0, 1.0};
  glm::dvec2 uv{0.0};
  std::uint32_t primitive = 0;
};

// A point drawn on a shape's surface for light sampling: pdf is per unit of
// area in the frame the point is given in.
struct AreaSample {
  glm::dvec3 p{0.0};
  glm::dvec3 n{0.0, 0.0, 1.0};
  double pdf_area = 0.0;
};

}  // namespace skyfarm

// TriangleBvh: the acceleration structure over a scene's triangle meshes and
// their instances, with closest-hit and any-hit (shadow) queries.
//
// Parameters
//   meshes     triangle meshes as plain arrays: positions (metres, the mesh's
//              own frame) and indices, 3 per triangle.  A mesh is drawn only
//              where an instance places it.
//   instances  a mesh id and a 4x4 object-to-world transform (doubles, affine,
//              invertible).  Instance ids are the positions in this vector;
//              geometry ids are mesh ids; primitive ids are triangle indices.
//   options    build_threads: threads Embree may use to build (0: all).  The
//              hits do not depend on it.
//
// Precision contract
//   Rays are given in the observer's local east-north-up frame (metres, origin
//   near the observer), never in planet-centred coordinates: Embree traverses
//   in single precision, and at 6.4e6 m a float step is 0.5 m.  Embree only
//   proposes candidate triangles; every candidate is re-intersected in double
//   precision (intersect_triangle, in the instance's frame through the double
//   inverse transform) and that test alone decides t, u, v and the hit point
//   (origin + t * dir, in doubles).  The closest hit is the smallest
//   (t, instance, primitive) among the candidates, so exact ties go to the
//   lowest ids whatever the BVH's shape or traversal order.  Two passes: the
//   float-closest confirmed hit, then every candidate within a window of
//   1e-5 * (t + extent) around its double t (extent: the largest coordinate
//   magnitude of the scene's world bounds), so a triangle whose double t
//   beats it is not lost to Embree's float t being a little larger.
//   What the float traversal can still miss: a ray that crosses a triangle
//   within float rounding of its edge (float says outside, double inside), a
//   band about 1e-7 of the coordinates wide (some 2 mm at 20 km; wider at
//   grazing incidence).  Only there can the hit depend on the CPU Embree runs
//   on (its SSE and AVX kernels round differently); shared edges of one mesh
//   stay closed (both triangles use the same float vertices).
//   Hits are counted for t in (0, tmax]; the caller offsets origins off the
//   surface they leave.
//
// An empty scene (no triangles in any instance) creates no Embree device and
// every query misses.  Queries are const and may run from many threads.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace skyfarm::accel {

struct MeshArrays {
  std::vector<glm::dvec3> positions;   // metres, the mesh's own frame
  std::vector<std::uint32_t> indices;  // 3 per triangle, into positions
};

struct Instance {
  std::uint32_t mesh = 0;                       // index into the meshes
  glm::dmat4 object_to_world = glm::dmat4(1.0); // affine, invertible
};

struct BvhHit {
  double t = 0.0;                // along dir, in units of |dir|
  std::uint32_t instance = 0;    // index into the instances
  std::uint32_t mesh = 0;        // the instance's mesh (geometry id)
  std::uint32_t primitive = 0;   // triangle index in the mesh
  double u = 0.0, v = 0.0;       // barycentrics: weights of the triangle's 2nd and 3rd vertex
  glm::dvec3 point{0.0};         // origin + t * dir, world frame
};

struct BvhBuildOptions {
  unsigned build_threads = 0;  // 0: all the machine's threads
};

class TriangleBvh {
 public:
  TriangleBvh(std::vector<MeshArrays> meshes, std::vector<Instance> instances,
              BvhBuildOptions options = {});
  ~TriangleBvh();
  TriangleBvh(TriangleBvh&&) noexcept;
  TriangleBvh& operator=(TriangleBvh&&) noexcept;
  TriangleBvh(const TriangleBvh&) = delete;
  TriangleBvh& operator=(const TriangleBvh&) = delete;

  // True when the scene has no triangle: no Embree device exists.
  bool empty() const;

  std::optional<BvhHit> closest_hit(const glm::dvec3& origin, const glm::dvec3& dir,
                                    double tmax) const;
  // Whether any triangle is hit for t in (0, tmax]: the same answer as
  // closest_hit(origin, dir, tmax).has_value(), found sooner.
  bool occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tmax) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skyfarm::accel

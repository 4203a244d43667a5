// The production SceneObjects: a request's objects (object_spec.h) placed in
// the observer's local east-north-up frame and intersected there.
//
// Frame.  ENU's origin is the ground point below the camera, planet-centred
// (0, 0, R).  A planet-centred ray's origin arrives in ENU exactly
// (geometry/enu_frame.h: Sterbenz), so every shape is intersected at the
// precision of its own size, not of the planet's; the hit goes back to
// planet-centred coordinates, whose rounding (~5e-10 m) the hit's offset
// covers.
//
// Shapes.  Sphere, disc, rectangle and box are the analytic unit shapes of
// geometry/ carried into each object's frame by its placement; a bounding
// sphere in ENU skips the objects a ray passes by.  Meshes go into one
// TriangleBvh (accel/triangle_bvh.h, Embree with double-precision hits), one
// BVH mesh per asset and one instance per object, so a mesh placed many
// times is stored once.  A scene without meshes builds no BVH.
//
// Hits.  n is the outward geometric normal (the +z side of a disc or a
// rectangle, the counter-clockwise side of a triangle), carried by the
// inverse transpose (a mirroring scale keeps it outward); tangent is the
// object's x axis made perpendicular to n (its y axis where x is along n):
// the roughness_x direction of an anisotropic material.  solid says whether
// the object encloses a volume (sphere, box, a mesh whose every edge is
// shared by exactly two triangles): only a solid can be glass.  offset_m is
// twice the hit point's rounding bound plus the planet-centred rounding.
#pragma once

#include <memory>
#include <vector>

#include "common/accel/triangle_bvh.h"
#include "common/assets/mesh_source.h"
#include "common/geometry/enu_frame.h"
#include "common/geometry/transform.h"
#include "common/objects/object_spec.h"
#include "common/render/scene_objects.h"

namespace skyfarm {

class PlacedObjects final : public SceneObjects {
 public:
  // `ground_radius_m`: the planet's radius (the ENU origin's distance from
  // the centre).  `meshes` resolves mesh assets (may be null without mesh
  // objects).  Throws std::invalid_argument for a bad placement or material
  // and std::runtime_error when a mesh cannot be had, naming the object
  // ("objects[2]").
  PlacedObjects(const std::vector<ObjectSpec>& objects, double ground_radius_m, const assets::MeshSource* meshes);
  ~PlacedObjects() override;

  std::optional<SurfaceHit> intersect(const Ray& ray, double t_max) const override;
  bool occluded(const Ray& ray, double t_max) const override;

  std::size_t object_count() const { return objects_.size(); }
  std::size_t triangle_count() const { return triangles_; }
  // Whether a BVH was built (the scene has mesh objects).
  bool has_bvh() const { return bvh_ != nullptr; }

 private:
  struct Object {
    ShapeKind shape;
    Transform to_enu;         // object -> ENU
    Transform to_object;      // ENU -> object
    glm::dvec3 bound_centre;  // ENU bounding sphere
    double bound_radius;
    bool solid;
    std::unique_ptr<material::Surface> surface;
    std::uint32_t mesh = 0;   // index into meshes_ (mesh objects)
  };
  struct ObjectHit {
    ShapeHit hit;  // in ENU
    std::size_t object;
  };
  std::optional<ObjectHit> closest(const Ray& enu, double t_max) const;
  SurfaceHit surface_hit(const ObjectHit& h) const;

  EnuFrame enu_;
  std::vector<Object> objects_;
  std::vector<std::size_t> analytic_;     // indices of the analytic objects
  std::vector<std::size_t> instance_of_;  // BVH instance -> object
  std::vector<std::shared_ptr<const assets::TriangleMesh>> meshes_;
  std::vector<bool> mesh_closed_;
  std::unique_ptr<accel::TriangleBvh> bvh_;
  std::size_t triangles_ = 0;
};

}  // namespace skyfarm

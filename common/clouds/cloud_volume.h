// A cloud volume placed in the scene: a VolumeGrid (an uploaded OpenVDB
// grid, common/assets/volume_grid.h) set in the observer's east-north-up
// frame by a Placement, as objects are (common/geometry/placement.h).
//
// Parameters
//   grid            the density grid; its frame's metres are the placed
//                   object's: x right (east before rotating), y forward
//                   (north), z up.  A file made Y-up (Houdini) stands up with
//                   rotate_deg [0, 90, 0] (pitch 90 turns +y to up)
//   placement       grid frame -> local ENU: p_enu = translate + R (scale * p_grid)
//   density_scale   extinction coefficient, m^-1, where the grid's value is 1
//                   (finite, >= 0)
//   optics          the particles' albedo and phase function (cloud_optics.h)
//   ground_radius_m the planet's radius: the ENU frame's origin is on the
//                   ground below the observer (as for placed objects)
//
// The field: sigma_t(p) = density_scale * trilinear(grid) at p's continuous
// index coordinates u (voxel centres at integers), the grid's values taken as
// 0 outside it, so the cloud fades to nothing one voxel beyond the outermost
// centres.  Along a ray through the interior the optical depth of a grid of
// constant value v is density_scale * v * the length of the voxels' cells.
//
// Majorants: the index box [-1, n] is cut into bricks of 8^3 voxels; a
// brick's bound is density_scale times the largest voxel its trilinear
// support can reach, with a spare voxel each side (so a point that rounding
// puts just outside its brick is still bounded).  for_each_majorant walks the
// bricks a ray crosses by 3-D DDA (Amanatides and Woo 1987) in index space,
// where the affine map keeps the ray's t, skips empty bricks and merges
// neighbours of equal bound.
#pragma once
#include <memory>
#include <vector>

#include "common/assets/volume_grid.h"
#include "common/clouds/cloud_field.h"
#include "common/geometry/enu_frame.h"
#include "common/geometry/placement.h"
#include "common/geometry/transform.h"

namespace skyfarm {

class CloudVolume : public CloudField {
 public:
  static constexpr int kBrickVoxels = 8;

  // Throws std::invalid_argument for an empty grid, a bad placement or density scale.
  CloudVolume(std::shared_ptr<const assets::VolumeGrid> grid, const Placement& placement, double density_scale,
              CloudOptics optics, double ground_radius_m);

  double sigma_t(const glm::dvec3& p) const override;
  void for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const override;
  const CloudOptics& optics() const override { return optics_; }
  double bottom_altitude_m() const override { return bottom_m_; }
  double top_altitude_m() const override { return top_m_; }

  // The field at continuous index coordinates (tests).
  double sigma_t_at_index(const glm::dvec3& u) const;
  // ENU point -> index coordinates and back (tests).
  glm::dvec3 index_from_enu(const glm::dvec3& enu) const { return enu_to_index_.point(enu); }
  glm::dvec3 enu_from_index(const glm::dvec3& u) const { return enu_to_index_.inverse().point(u); }
  const EnuFrame& enu_frame() const { return enu_; }
  glm::ivec3 brick_counts() const { return bricks_; }

 private:
  double brick_majorant(int bx, int by, int bz) const {
    return majorants_[static_cast<std::size_t>(bx) +
                      static_cast<std::size_t>(bricks_.x) *
                          (static_cast<std::size_t>(by) + static_cast<std::size_t>(bricks_.y) * static_cast<std::size_t>(bz))];
  }

  std::shared_ptr<const assets::VolumeGrid> grid_;
  double density_scale_;
  CloudOptics optics_;
  EnuFrame enu_;
  Transform enu_to_index_;
  glm::ivec3 bricks_{0};
  std::vector<double> majorants_;  // per brick, x fastest
  double bottom_m_ = 0.0, top_m_ = 0.0;
};

}  // namespace skyfarm

// A procedural cloud layer: a spherical shell between base_m and
// base_m + thickness_m above the ground, filled by a deterministic density
// assembled as Schneider (2015, 2017, "The real-time volumetric cloudscapes
// of Horizon Zero Dawn") and Hillaire (2016) describe:
//
//   density(p) = erode(coverage_shape(q) * profile(h), detail(q)),   q = p - wind * time
//
//   coverage_shape  value-noise fBm on a cubic lattice of scale_m in
//                   planet-centred coordinates, remapped by the coverage so
//                   that coverage 0 gives no cloud anywhere and 1 full cloud
//                   everywhere;
//   profile(h)      the type's height profile over the layer, in [0, 1]
//                   (cumulus: a quick rise above the base and a rounded top;
//                   stratus: a slab with soft edges; ...);
//   detail          periodic Worley / value noise of detail_scale_m, baked
//                   once into a small tiled 3-D table, eating the edges by
//                   `erosion`;
//   sigma_t(p)      = sigma_max * density(p), sigma_max from the water content
//                   and the optics (or from the requested optical depth).
//
// Every step is monotone in the coverage shape, so a lattice cell's bound is
// the density at its shape's largest corner: the majorant grid is exact.
// Pure functions of the spec: the same bits on every worker.
#pragma once
#include <memory>

#include "common/clouds/cloud_field.h"
#include "common/clouds/cloud_spec.h"

namespace skyfarm {

class CloudLayer : public CloudField {
 public:
  // planet_radius_m: the ground's radius; time_s: seconds since J2000 that
  // the wind has blown (0 when the render has no time).
  CloudLayer(const CloudLayerSpec& spec, double planet_radius_m, double time_s);
  ~CloudLayer() override;

  double sigma_t(const glm::dvec3& p) const override;
  void for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const override;
  const CloudOptics& optics() const override;
  double bottom_altitude_m() const override;
  double top_altitude_m() const override;

  // The density in [0, 1] (sigma_t / sigma_max) and sigma_max.
  double density(const glm::dvec3& p) const;
  double sigma_max() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skyfarm

// A horizontally uniform cloud: a spherical shell of constant extinction
// between two altitudes, the plane-parallel slab of radiative-transfer texts
// when the planet is large.  The physics tests' cloud (reflectance and
// transmittance against an independent slab solution, Beer-Lambert), and a
// request's layer at coverage 1 with no erosion is the same medium.
//
// Parameters
//   bottom_m, top_m   altitudes above the planet's radius, 0 <= bottom < top
//   sigma_t           extinction, m^-1 (> 0)
//   optics            albedo and phase function
#pragma once
#include "common/clouds/cloud_field.h"

namespace skyfarm {

class UniformCloudSlab : public CloudField {
 public:
  UniformCloudSlab(double planet_radius_m, double bottom_m, double top_m, double sigma_t, CloudOptics optics);

  double sigma_t(const glm::dvec3& p) const override;
  void for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const override;
  const CloudOptics& optics() const override { return optics_; }
  double bottom_altitude_m() const override { return bottom_; }
  double top_altitude_m() const override { return top_; }

 private:
  double radius_, bottom_, top_, sigma_;
  CloudOptics optics_;
};

}  // namespace skyfarm

// The reflectance of a conductor's microfacet: Fresnel with a complex index
// (fresnel.h), or a perfect mirror (reflectance 1 at every angle, for white
// furnace tests and idealised metals).
//
// Parameters
//   eta            n + i k relative to the outside medium, n > 0, k >= 0.
//   perfect_mirror when true, eta is ignored and reflectance() is 1.
#pragma once

#include <complex>

#include "common/material/fresnel.h"

namespace skyfarm::material {

struct ConductorFresnel {
  std::complex<double> eta{1.0, 0.0};
  bool perfect_mirror = false;

  static ConductorFresnel mirror() { return {{1.0, 0.0}, true}; }

  double reflectance(double cos_theta) const {
    return perfect_mirror ? 1.0 : fresnel_conductor(cos_theta, eta);
  }
};

}  // namespace skyfarm::material

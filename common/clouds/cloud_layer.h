// A procedural cloud layer: a spherical shell between base_m and
// base_m + thickness_m above the ground, filled by a deterministic density
// assembled as Schneider (2015, 2017, "The real-time volumetric cloudscapes
// of Horizon Zero Dawn") and Hillaire (2016) describe:
//
//   density(p) = erode(shape(q) * profile(x), detail(q)),   q = p - drift_m,
//                x = (|p| - R - base_m) / thickness_m
//
//   shape        coverage remap of a value-noise fBm (value_noise.h): three
//                octaves, lattices of scale_m, scale_m / 2, scale_m / 4 in
//                planet-centred coordinates, weights 4/7, 2/7, 1/7; then
//                shape = clamp((fbm - lo) / w, 0, 1), w = 0.3,
//                lo = (1 - coverage)(1 + w) - w, so that coverage 0 gives
//                no cloud anywhere (fbm < 1) and 1 full cloud everywhere
//                (fbm >= 0).  The covered share of the area grows with the
//                coverage but is not equal to it (the fBm is not uniform);
//                docs/experiments/2026-12-07-cloud-layer.md has the measure.
//   profile(x)   the type's height profile (cloud_profile.h), in [0, 1];
//   detail       Worley noise of cells detail_scale_m (tiled_worley_noise.h),
//                a table of period 4 detail_scale_m;
//   erode(d, a)  = min(d, max(0, (d - a) / (1 - a))), a = erosion * detail
//                (Schneider's remap): eats thin edges, keeps the cores;
//   sigma_t(p)   = sigma_max * density(p); sigma_max = water_content_g_m3 x
//                the optics' extinction per g m^-3, or, when optical_depth
//                > 0, optical_depth / (thickness_m * integral of the profile):
//                the vertical optical depth where the coverage is full and
//                nothing erodes.
//
// The wind: drift_m is one constant planet-centred displacement, how far the
// air has moved; the noise is looked up at q = p - drift_m, an exact 3-D
// translation of the field (the height profile stays with |p|).  The render
// setup passes time x (wind_east, wind_north, 0): in the world frame of ray.h
// +x and +y are the observer's east and north, so over the observer's sky the
// shapes move with the wind; far away the translation is the same rigid one
// (no shear, however large the drift: seconds since J2000 x 10 m/s ~ 1e10 m).
// Lattice cells are 64-bit integers from floor(q / scale) in doubles.
//
// Majorants (cloud_field.h's contract, exact): every step is monotone in
// the fBm and in the profile, and erosion only lowers the density, so over
// a coarse cell of the scale_m lattice and an altitude range the density is
// at most shape(max of each octave's lattice values over the cell) x the
// profile's maximum over the range.  for_each_majorant steps through the
// cells the ray crosses inside the shell (shell_intervals.h, then a 3-D DDA,
// Amanatides & Woo 1987), splits each at kAltitudeBins altitude bins, skips
// cells whose bound is 0 (cloud-free air costs one bound per cell) and
// merges neighbours with equal bounds.
//
// Parameters: CloudLayerSpec (cloud_spec.h); planet_radius_m, the ground's
// radius; drift_m as above.  Throws std::invalid_argument for a spec out of
// range (coverage or erosion outside [0, 1], a thickness, scale or detail
// scale <= 0, a negative base, water content or optical depth).
// Pure functions of the spec: the same bits on every worker.
#pragma once
#include <memory>

#include <glm/vec3.hpp>

#include "common/clouds/cloud_field.h"
#include "common/clouds/cloud_spec.h"

namespace skyfarm {

class CloudLayer : public CloudField {
 public:
  static constexpr int kAltitudeBins = 8;

  CloudLayer(const CloudLayerSpec& spec, double planet_radius_m, const glm::dvec3& drift_m);
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

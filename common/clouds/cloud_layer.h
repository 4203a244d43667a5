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
//                shape = clamp((fbm - lo) / 0.1, 0, 1) with lo the fBm's
//                (1 - coverage) quantile (a measured table), so that the
//                share of the area holding cloud is the coverage; coverage 0
//                gives no cloud anywhere (lo = 1 > fbm) and 1 full cloud
//                everywhere (lo = -0.1: the ramp ends at fbm = 0).
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
// the fBm and in the profile, and erosion only lowers the density.  The
// majorant grid has cells of scale_m / 8, each inside one lattice cell of
// every octave, where value noise is largest at one of the box's corners
// (value_noise.h): the shape's bound is the remap of the sum over octaves of
// their corner maxima, times the profile's maximum over the piece's altitude
// range.  for_each_majorant steps through the cells the ray crosses inside
// the shell (shell_intervals.h, then a 3-D DDA, Amanatides & Woo 1987),
// splits each at kAltitudeBins altitude bins, skips cells whose bound is 0
// (cloud-free air costs one bound per cell) and merges neighbours with
// equal bounds.  A margin of a few ulps of the coordinates covers the
// rounding between the walk and sigma_t.
//
// Parameters: CloudLayerSpec (cloud_spec.h); planet_radius_m, the ground's
// radius; drift_m as above.  Throws std::invalid_argument for a spec out of
// range (coverage or erosion outside [0, 1], a thickness, scale or detail
// scale <= 0, a negative base, water content or optical depth; and
// cloud_optics' error for an effective radius outside its range).
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

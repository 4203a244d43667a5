// A control variate for the path tracer's Russian roulette: an approximation
//     c(p, wi, lambda) ~ L(p <- wi, lambda)
// of the radiance arriving at a point p from direction wi (sky and ground,
// every scattering order, without the sun disk), tabulated once per job from
// the LUT sky (Hillaire 2020, common/lut/: the same atmosphere and sun).
//
// Roulette with a control (VolumePathIntegrator::survives): where plain
// roulette ends a path with probability 1 - s and divides the survivors by s,
// the estimate of the rest of the path X becomes
//     c                          if the path ends,
//     c + (X - c) / s            if it goes on,
// whose expectation is E[X] for ANY c fixed before the coin (the identity
// of control variates), so c's errors cost variance, never bias.  The
// variance roulette adds falls from (1/s - 1) E[X]^2 to (1/s - 1) (E[X] - c)^2.
// The LUT's isotropic multiple scattering is within about 25 % of the path
// tracer by day (lut_sky.h), so most of roulette's variance goes; the rest
// of the path's own noise stays.  The table is coarse on purpose: from
// 16 x 32 x 17 x 16 nodes (0.3 s to build) down to 8 x 16 x 5 x 8 the noon
// image's error at equal samples did not move (1.75 %; 4 x 8 x 3 x 4: 1.77 %),
// and the LUT it marches through is coarse too (lut_resolution).
//
// Table (float, interpolated multilinearly in all four coordinates and
// linearly between bin centres in wavelength):
//   altitude   h in [0, top], nodes uniform in sqrt(h / top) (dense low)
//   view       mu = cos(zenith of wi), nodes uniform in +-sqrt of the
//              distance to the horizon's mu_h = -sqrt(1 - (R/r)^2), on each
//              side of it (the sky/ground edge)
//   sun        the sun's zenith angle at p, in a window around its angle at
//              the observer: +-sun_window_deg plus the angle (from the
//              planet's centre) out to the observer's horizon (paths stay
//              near the camera; outside the window the edge is used: c is
//              then poorer, the estimate still unbiased)
//   azimuth    cos of the azimuth between wi and the sun about p's vertical,
//              nodes uniform in it (dense towards and away from the sun)
//   bins       spectral bins of the LUT over the scene's wavelengths, at
//              most one per 20 nm (one bin for a range of a few nm)
// Each node is LutSky::raymarch_radiance with `steps` steps.
#pragma once
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "common/lut/lut_sky.h"
#include "common/render/scene.h"
#include "common/spectrum/sampled_spectrum.h"
#include "common/spectrum/wavelength_sampling.h"

namespace skyfarm {

struct RadianceControlResolution {
  int altitudes = 8, view_rows = 16, sun_angles = 5, azimuths = 8;
  int bins = 8, steps = 8;
  double sun_window_deg = 12.0;
};

class RadianceControl {
 public:
  explicit RadianceControl(const Scene& scene, const RadianceControlResolution& resolution = {});

  // c at the path's wavelengths (W m^-2 sr^-1 nm^-1, >= 0 and finite); p
  // planet-centred, wi unit.
  SampledSpectrum radiance(const glm::dvec3& p, const glm::dvec3& wi, const SampledWavelengths& lambda) const;

  int bins() const { return bins_; }
  // The LUT sky the nodes are marched through: coarse tables (a control
  // needs no more; see above), `bins` spectral bins.
  static LutResolution lut_resolution(int bins);
  // The tabulated value at node (altitude a, view row m, sun angle s,
  // azimuth k), bin b (tests).
  float node(int a, int m, int s, int k, int b) const { return values_[index(a, m, s, k) + static_cast<std::size_t>(b)]; }
  // The point and direction of a node (tests: c there equals the LUT's march).
  void node_geometry(int a, int m, int s, int k, glm::dvec3* p, glm::dvec3* wi) const;
  std::size_t memory_bytes() const { return values_.size() * sizeof(float); }

 private:
  struct Coordinate {  // a fractional table position: node i and weight of i + 1
    int i = 0;
    double f = 0.0;
  };
  std::size_t index(int a, int m, int s, int k) const {
    return ((((static_cast<std::size_t>(a) * res_.view_rows + static_cast<std::size_t>(m)) * res_.sun_angles +
              static_cast<std::size_t>(s)) * res_.azimuths + static_cast<std::size_t>(k)) *
            static_cast<std::size_t>(bins_));
  }
  double altitude_of(int a) const;
  double mu_of(int m, double r) const;
  double sun_zenith_of(int s) const;
  double cos_azimuth_of(int k) const;
  static Coordinate coordinate(double x, int nodes);  // x in node units, clamped

  RadianceControlResolution res_;
  double R_ = 0.0, top_ = 0.0;
  glm::dvec3 sun_{0.0, 0.0, 1.0};
  double sun_zenith_lo_ = 0.0, sun_zenith_step_ = 0.0;  // the window's first node and spacing, rad
  int bins_ = 1;
  double lambda_min_ = 0.0, bin_width_ = 0.0;
  std::vector<float> values_;
};

}  // namespace skyfarm

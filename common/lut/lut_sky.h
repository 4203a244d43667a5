// The LUT renderer's sky: Hillaire's (2020) table-based sky,
// spectral, on the same atmosphere model (Atmosphere, Sun) as the path tracer.
// Fast and approximate; its error against the path tracer is measured in
// tests/common/lut/sky_view_lut_test.cpp, never assumed.
//
// Parameters (LutResolution; defaults after Hillaire 2020 except where noted)
//   spectral_bins              equal bins over [lambda_min, lambda_max]
//                              (default 32: see the table below)
//   medium_altitude_samples    coefficient table nodes (2048), medium_table.h
//   phase_samples              tabulated phase function nodes (512)
//   transmittance_mu/_r/_steps 256 x 128 nodes, 64 quadrature intervals per
//                              part of a ray (transmittance_lut.h)
//   multiple_scattering_*      32 mu_s x 32 altitudes, 64 directions (32 mirror-
//                              paired rings), 20 steps
//   ground_irradiance_*        64 mu_s, 64 directions, 20 steps
//   bands, bands_*             bands l = 1..2 of the second order's
//                              direction dependence: 24 mu_s x 8 altitudes,
//                              12 x 6 directions, 8 steps
//                              (multiple_scattering_bands.h)
//   sky_view_band_*            the sky-view table adds the bands on every
//                              4th row and 8th column, 16 steps
//   sky_view_*                 192 azimuths x 108 zenith rows, 30 steps
//   aerial_*                   32 x 32 x 32 slices up to 64 km
//   space_view_steps           march steps of a view from above the top (64)
//
// Observers inside the atmosphere (altitude <= top) read the sky-view table
// (sky and ground) and the aerial-perspective table; observers above the
// top get a march per ray (raymarch_radiance) through the transmittance,
// multiple-scattering and ground-irradiance tables.  The sun disk adds
// Sun::radiance (bin mean) times the transmittance of the view ray.
//
// Units: radiance W m^-2 sr^-1 nm^-1 per bin (the value at the bin centre of
// a sun spectrum averaged over the bin; spectral_grid.h), transmittance 1.
// Every output is finite and >= 0: a value that is not (impossible by
// construction: all tables are sums of non-negative terms and interpolated
// with convex weights) is replaced by 0 and counted in sanitized_values(),
// which tests require to stay 0.  A LutSky is immutable once built; all its
// const methods may be called from many threads at once, and copies share
// the tables (with_sun shares the atmosphere's tables between suns).
//
// Spectral bins needed for colour (tests/bench/lut_bench.cpp
// BM_LutBinCountColourError): XYZ of the sky-view radiance with N bins over
// 360-830 nm against N = 94 (5 nm bins), Earth preset, AM0 sun, observer on
// the ground, 45 directions (zenith 0, 30, 60, 80, 88, 90 = the horizon, 95,
// 120, 180 deg x 10-180 deg from the sun's azimuth); worst relative
// luminance error |Y/Y_94 - 1| and worst CIE 1931 xy distance per sun zenith:
//      N   sun 30 deg      sun 80 deg      sun 90 deg      sun 96 deg
//      4   2.4 % 0.023     2.1 % 0.037     23 %  0.058     57 %  0.100
//      8   0.73 % 0.0076   1.2 % 0.0090    3.0 % 0.0145    7.3 % 0.029
//     12   0.38 % 0.0011   0.69 % 0.0017   1.0 % 0.0040    3.3 % 0.0100
//     16   0.33 % 0.0027   0.68 % 0.0037   1.7 % 0.0056    3.7 % 0.0089
//     24   0.11 % 0.0003   0.22 % 0.0004   0.34 % 0.0011   0.41 % 0.0024
//     28   0.10 % 0.0008   0.16 % 0.0010   0.42 % 0.0012   0.96 % 0.0022
//     32   0.09 % 0.0003   0.07 % 0.0003   0.15 % 0.0006   0.41 % 0.0013
// Only N = 32 meets < 1 % in luminance and < 0.002 in xy everywhere,
// twilight included (the light that crossed the ozone layer along the
// horizon is the least smooth spectrum); 16 bins suffice by day for
// luminance (< 1 %), not for xy (0.003-0.004).  Default: 32.
//
// Accuracy against the path tracer (tests/common/lut/sky_view_lut_test.cpp;
// Earth preset with ground albedo 0.3, 440-680 nm): single scattering agrees
// to < 1 %; the higher orders are Hillaire's isotropic term plus the
// multiple-scattering bands (multiple_scattering_bands.h): LUT/PT - 1 over
// 5 directions x 4 wavelengths is -5 % (blue, 1 deg above the horizon) to
// +5 % (red, anti-solar sky 60 deg up) at noon (sun 30 deg) and -16 % (blue,
// 5 deg above the horizon) to +2 % with the sun at 80 deg.  Hillaire's term
// alone erred by -19 % to +24 % and -28 % to +6 %: it spreads the light of
// the aerosols' forward peak over all directions.  At twilight (sun 93 deg)
// the bands make the sky brighter than the path tracer's away from the sun
// (docs/experiments/2026-12-07-anisotropic-multiple-scattering.md).
//
// Cost (tests/bench/lut_bench.cpp, one core, CPU time, 8 / 32 bins,
// observer on the ground): all tables about 21 / 35 ms with the multiple-
// scattering bands (15 / 23 ms without them: the bands table 12 ms, the
// sky view 8.2 ms instead of 6.1) on the Xeon VM they were last measured
// on (medians of 5; faster VMs take ~0.7x), the sun-dependent tables alone
// (with_sun) about 8.6 ms at 32 bins; one radiance look-up ~0.1 us; memory
// 5.7 / 16.4 MB (whole 2 MiB pages, huge_page_allocator.h).  Where the time
// goes, what bounds it and how it got there:
// docs/experiments/*-lut-build-time.md.  A timelapse or a cache of many suns
// should build once and call with_sun.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/atmosphere/atmosphere.h"
#include "common/lut/refracted_view.h"
#include "common/lut/spectral_grid.h"
#include "common/sun/sun.h"

namespace skyfarm {

class SkyViewLut;
class AerialPerspectiveLut;

struct LutResolution {
  int spectral_bins = static_cast<int>(kDefaultLutBins);
  int medium_altitude_samples = 2048;
  int phase_samples = 512;
  int transmittance_mu = 256, transmittance_r = 128, transmittance_steps = 64;
  int multiple_scattering_mu_s = 32, multiple_scattering_altitude = 32;
  int multiple_scattering_directions = 64, multiple_scattering_steps = 20;
  int ground_irradiance_mu_s = 64, ground_irradiance_directions = 64, ground_irradiance_steps = 20;
  int sky_view_azimuth = 192, sky_view_zenith = 108, sky_view_steps = 30;
  // Multiple-scattering bands (multiple_scattering_bands.h): highest band
  // (0: Hillaire's isotropic term alone), nodes, directions, steps; and
  // the sky-view table's coarse grid for them (sky_view_lut.h).
  int bands = 2;
  int bands_mu_s = 24, bands_altitude = 8, bands_rings = 12, bands_azimuths = 6, bands_steps = 8;
  int sky_view_band_row_stride = 4, sky_view_band_column_stride = 8, sky_view_band_steps = 16;
  int aerial_azimuth = 32, aerial_zenith = 32, aerial_slices = 32;
  double aerial_max_distance_m = 64000.0;
  int space_view_steps = 64;
};

class LutSky {
 public:
  // All tables for one atmosphere, sun and observer altitude (m above the
  // ground, on the observer frame's +z axis).  Throws std::invalid_argument
  // for a bad range or resolution.
  static LutSky build(const Atmosphere& atmosphere, const Sun& sun, double observer_altitude_m, double lambda_min_nm,
                      double lambda_max_nm, const LutResolution& resolution = {});
  // The same atmosphere tables (shared, not rebuilt) for another sun and/or
  // observer altitude: only the sky-view and aerial-perspective tables are built.
  LutSky with_sun(const Sun& sun) const { return with_sun(sun, observer_altitude_m_); }
  LutSky with_sun(const Sun& sun, double observer_altitude_m) const;
  // The same sky seen through refraction ("atmosphere.refraction",
  // refracted_view.h: the look-up's directions mapped, the tables shared).
  LutSky refracted() const;
  // Where the sun's light from the true direction d shows in radiance() (d
  // itself without refraction, its apparent direction at 550 nm with), and
  // the solid angle ratio there (1, or dw_apparent / dw_true): a splat of
  // the disk samples the true disk and puts each sample there, its solid
  // angle times the ratio.  nullopt where the planet hides it.
  std::optional<RefractedView::Apparent> disk_sample_direction(const glm::dvec3& d) const;
  // Whether the view v (unit, observer frame) looks at the sun's disk: the
  // disk itself without refraction, the apparent (lifted, flattened) disk at
  // 550 nm with it.
  bool sees_sun_disk(const glm::dvec3& v) const;

  const SpectralGrid& grid() const;
  // E_sun and the disk's radiance per bin (bin means).
  std::span<const double> sun_irradiance() const { return sun_E_; }
  std::span<const double> sun_disk_radiance() const { return sun_L_; }
  double observer_altitude_m() const { return observer_altitude_m_; }
  bool observer_above_atmosphere() const { return above_; }

  // Radiance arriving at the observer from view_dir (unit, observer frame:
  // z up, y north, x east), out_per_bin.size() >= grid().size().  The sky-
  // view table (plus ground) inside the atmosphere, a march from above it.
  void radiance(const glm::dvec3& view_dir, std::span<double> out_per_bin, bool include_sun_disk) const;
  // In-scattered radiance and transmittance between the observer and a point
  // at distance_m along view_dir (aerial-perspective table up to its
  // max distance, a march beyond it or from above the atmosphere).
  void aerial_perspective(const glm::dvec3& view_dir, double distance_m, std::span<double> in_scattered,
                          std::span<double> transmittance) const;

  // Reference-quality march of one ray through the transmittance, multiple-
  // scattering and ground-irradiance tables (exact phase functions, `steps`
  // steps placed by lut::place_steps); origin planet-centred, m.  An origin
  // above the top moves to where the ray enters; rays that miss the
  // atmosphere see 0 (plus the sun disk).  Also used for views from space.
  void raymarch_radiance(const glm::dvec3& origin_planet_centred, const glm::dvec3& dir, std::span<double> out_per_bin,
                         bool include_sun_disk, int steps) const;
  // The same over [0, distance_m] without the ground: L_in and T.
  void raymarch_aerial_perspective(const glm::dvec3& origin_planet_centred, const glm::dvec3& dir, double distance_m,
                                   std::span<double> in_scattered, std::span<double> transmittance, int steps) const;

  // The air's transmittance from radius r (m, planet-centred) along cosine mu
  // (to the local zenith) to the top of the atmosphere, per bin: the
  // transmittance table, 0 where the planet hides the direction.
  void transmittance_to_top(double r, double mu, std::span<double> out) const;
  double planet_radius_m() const;
  const Sun& sun() const { return *sun_; }

  std::size_t memory_bytes() const;
  // Outputs replaced by 0 because they were negative or not finite (see above).
  std::uint64_t sanitized_values() const;
  // Multiple-scattering nodes whose f_ms was clamped below 1 (dense media).
  int clamped_multiple_scattering_nodes() const;

  struct Tables;  // the atmosphere's tables (lut_sky.cpp)

 private:
  void march(const glm::dvec3& origin, const glm::dvec3& dir, double t_max, int steps, bool ground, bool sun_disk,
             double* L, double* T) const;
  void sanitize(std::span<double> values) const;
  void refracted_radiance(const glm::dvec3& v, std::span<double> out, bool include_sun_disk) const;

  std::shared_ptr<const Tables> tables_;
  std::shared_ptr<const SkyViewLut> sky_view_;          // null above the atmosphere
  std::shared_ptr<const AerialPerspectiveLut> aerial_;  // null above the atmosphere
  std::shared_ptr<std::atomic<std::uint64_t>> sanitized_;
  std::shared_ptr<const Sun> sun_;
  std::shared_ptr<const RefractedView> refraction_;  // null: straight rays
  LutResolution resolution_;
  std::vector<double> sun_E_, sun_L_;
  double observer_altitude_m_ = 0.0, observer_r_ = 0.0;
  bool above_ = false;
};

}  // namespace skyfarm

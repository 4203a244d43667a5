// Hillaire's (2020, §5.3) sky-view table: the radiance per spectral bin that
// an observer inside the atmosphere receives from every direction, for one
// sun position, on the (azimuth relative to the sun, zenith) layout of
// view_mapping.h (rows split at the horizon, crowded towards it).
//
// Parameters
//   azimuth_columns   default 192 (phi in [0, pi], denser towards the sun)
//   zenith_rows       default 108 (54 sky rows + 54 ground rows)
//   steps             march steps per row (default 30, lut::place_steps)
//
// Each entry is scattering_march.h's radiance times the sun's irradiance per
// bin, W m^-2 sr^-1 nm^-1: single scattering with the sun's visibility from
// the transmittance LUT (so at twilight the sunlit upper air still shines),
// plus sigma_s Psi_ms, plus, for rows that meet the ground, the ground's
// Lambertian reflection of the sun and of the sky (ground irradiance LUT)
// seen through the air in between.  The sun disk itself is not in the table
// (lut_sky.h adds it).
//
// With multiple-scattering bands (multiple_scattering_bands.h), their
// direction-dependent second-order light is marched on a coarser grid of
// the same layout (every row_stride-th row of each half and every
// column_stride-th column, plus each half's last row and the last column,
// with `steps` steps), interpolated bilinearly within each half and added;
// an entry that the bands would make negative is clamped to 0.  The bands
// change smoothly over the sky (they are a few harmonics), so the coarse
// grid costs little accuracy and a fraction of the full grid's look-ups.
//
// Cost: the march of each row (steps, coefficients, exponentials) is done
// once and shared by all its columns, which only repeat the sun-dependent
// look-ups (rows share the altitude profile of their zenith angle); those
// dominate (108 x 192 x 30 of them,
// docs/experiments/2026-11-22-lut-build-time.md).  Stored in single precision (2.7 MB at 32 bins; the table's own
// error is ~1 %).
#pragma once
#include <cstddef>
#include <span>
#include <vector>

#include "common/core/huge_page_allocator.h"
#include "common/lut/ground_irradiance_lut.h"
#include "common/lut/medium_table.h"
#include "common/lut/multiple_scattering_lut.h"
#include "common/lut/transmittance_lut.h"
#include "common/lut/view_mapping.h"

namespace skyfarm {

class MultipleScatteringBands;

// Where the sky-view table evaluates the bands (above).
struct BandViewGrid {
  int row_stride = 4, column_stride = 8, steps = 16;
};

class SkyViewLut {
 public:
  // observer_radius_m: R <= r <= R_top; mu_s: cos of the sun's zenith angle
  // at the observer; sun_irradiance: E_sun per bin, W m^-2 nm^-1.
  static SkyViewLut build(const MediumTable& medium, const TransmittanceLut& transmittance,
                          const MultipleScatteringLut& multiple_scattering, const GroundIrradianceLut& ground,
                          double observer_radius_m, double mu_s, std::span<const double> sun_irradiance,
                          int azimuth_columns = 192, int zenith_rows = 108, int steps = 30,
                          const MultipleScatteringBands* bands = nullptr, const BandViewGrid& band_grid = {});

  // Radiance per bin for a view with zenith cosine mu and cos(phi), phi the
  // azimuth from the sun's (bilinear within the sky or the ground half).
  void lookup(double mu, double cos_phi, double* out) const;

  const lut::ViewMapping& mapping() const { return mapping_; }
  std::size_t memory_bytes() const { return table_memory_bytes(values_); }

 private:
  void add_bands(const MediumTable& medium, const TransmittanceLut& transmittance, const MultipleScatteringBands& bands,
                 double r, double mu_s, std::span<const double> sun_irradiance, const BandViewGrid& grid);

  int bins_ = 0;
  lut::ViewMapping mapping_;
  TableVector<float> values_;  // [row][column][bin], single precision (2.7 MB instead of 5.3 at 32 bins)
};

}  // namespace skyfarm

// Aerial perspective (Hillaire 2020 §5.4): the light the air adds between the
// observer and an object at distance d inside the atmosphere, and the
// transmittance that dims the object, per spectral bin, for one sun
// position:
//   L_seen = T(d) L_object + L_in(d).
// Hillaire's table follows the camera frustum; this one covers all
// directions around the observer, on the sky-view layout (view_mapping.h)
// times distance slices.
//
// Parameters
//   azimuth_columns   default 32
//   zenith_rows       default 32 (16 sky + 16 ground rows)
//   slices            distance nodes per direction, default 32, at
//                     d_k = d_end (k/(n-1))^2 (quadratic: fine near the observer)
//   max_distance_m    default 64 km
//
// One march step per slice interval (its midpoint), scattering_march.h
// without the ground term: L_in(d) is single scattering plus sigma_s Psi_ms,
// times E_sun, in W m^-2 sr^-1 nm^-1.  Each row's slices end at
//   d_end = min(max_distance, distance to the ground or to the top),
// so a row that meets the ground has a node exactly on it (where the
// in-scattered light and the transmittance change fastest).  A look-up
// computes d_end of its own direction and reads both neighbouring rows at
// the same fraction d / d_end (linear in sqrt(d / d_end) between slices),
// holding the value at d_end beyond it: an object on the ground reads the
// rows' ground values.  The transmittance depends on the
// zenith angle only and is kept per row.
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

class AerialPerspectiveLut {
 public:
  static AerialPerspectiveLut build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                    const MultipleScatteringLut& multiple_scattering, double observer_radius_m,
                                    double mu_s, std::span<const double> sun_irradiance, int azimuth_columns = 32,
                                    int zenith_rows = 32, int slices = 32, double max_distance_m = 64000.0);

  // L_in and T per bin for a view (zenith cosine mu, cos(phi) from the sun)
  // and a distance, clamped to [0, max_distance_m()].
  void lookup(double mu, double cos_phi, double distance_m, double* L_in, double* T) const;

  double max_distance_m() const { return d_max_; }
  const lut::ViewMapping& mapping() const { return mapping_; }
  std::size_t memory_bytes() const { return table_memory_bytes(L_) + table_memory_bytes(T_); }

 private:
  int bins_ = 0, slices_ = 0;
  double d_max_ = 0.0, R_top_ = 0.0;
  lut::ViewMapping mapping_;
  std::vector<double> end_;  // [row]: the distance of the last slice
  TableVector<float> L_;     // [row][column][slice][bin], single precision (as the sky view)
  TableVector<float> T_;     // [row][slice][bin]
};

}  // namespace skyfarm

// Irradiance of the sky on a horizontal ground, I(mu_s) per spectral bin and
// per unit solar irradiance at the top of the atmosphere (dimensionless): the
// light that lets the ground glow under a blue sky and at twilight.
// (Bruneton 2017 keeps the same quantity, "irradiance", as a 2-D texture; on
// the ground only mu_s matters.)
//
// Parameters
//   mu_s_samples   nodes on mu_s in [-1, 1], equally spaced (default 64)
//   directions     cosine-weighted Fibonacci directions over the upper
//                  hemisphere (default 64)
//   steps          march steps per direction (default 20)
//
//   I(mu_s) = int_{upper hemisphere} L_sky(w) cos(theta) dw
//           ~ (pi / n) sum_i L_sky(w_i)                    (fibonacci_directions.h)
// with L_sky the single-scattering radiance (true phase functions) plus
// Hillaire's multiple-scattering term, seen from the ground
// (scattering_march.h).  The ground's own light reflected back down by the
// atmosphere enters only through Psi_ms (which includes the sunlit ground as
// a second-order source); a dense, bright-ground scene underestimates I by
// the factor 1 / (1 - rho S), S the atmosphere's spherical albedo (a few
// per cent for clear Earth skies at 0.3 albedo).
#pragma once
#include <cstddef>
#include <vector>

#include "common/lut/medium_table.h"
#include "common/lut/multiple_scattering_lut.h"
#include "common/lut/transmittance_lut.h"

namespace skyfarm {

class GroundIrradianceLut {
 public:
  static GroundIrradianceLut build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                   const MultipleScatteringLut& multiple_scattering, int mu_s_samples = 64,
                                   int directions = 64, int steps = 20);

  // out[b] += I_b(mu_s) (linear in mu_s).
  void lookup_add(double mu_s, double* out) const;
  std::size_t memory_bytes() const { return values_.size() * sizeof(double); }

 private:
  int bins_ = 0, n_mu_s_ = 0;
  std::vector<double> values_;  // [mu_s node][bin]
};

}  // namespace skyfarm

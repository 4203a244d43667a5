// One path's majorants, shell by shell: sigma_maj at the path's
// kWavelengthsPerPath wavelengths for every shell of a ShellMajorants.
//
// Why: a path crosses hundreds of shells (camera ray, bounces, a shadow ray
// per collision), each time reading its wavelengths' majorants of that
// shell.  The table is bin-major (atmosphere_medium.h), so each of the path's
// bins is one short column of shells: the path keeps a pointer to each and
// the values it reads come from a few cache lines that stay in L1.  Nothing
// is copied per path (the rows used to be gathered from a shell-major table,
// four cache lines per shell, whether the path reached the shell or not).
// The values are the table's: same bits.
#pragma once
#include <array>
#include <cstddef>

#include "common/render/atmosphere_medium.h"

namespace skyfarm {

class PathMajorants {
 public:
  PathMajorants(const ShellMajorants& shells, const std::array<std::size_t, kWavelengthsPerPath>& bins)
      : shells_(shells) {
    for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) columns_[i] = shells.bin_column(bins[i]);
  }

  const ShellMajorants& shells() const { return shells_; }

  SampledSpectrum sigma_maj(std::size_t shell) const {
    SampledSpectrum m;
    for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) m.v[i] = columns_[i][shell];
    return m;
  }
  // The hero's (wavelength 0's) alone.
  double sigma_maj0(std::size_t shell) const { return columns_[0][shell]; }
  // tau += sigma_maj(shell) * length, read straight from the columns: the
  // same values and operations as through sigma_maj, without a spectrum
  // stored as 4 doubles and read back as 2 pairs (a store-forwarding stall
  // per pair on every shell crossed).
  void add_optical_depth(std::size_t shell, double length, SampledSpectrum* tau) const {
    for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) tau->v[i] += columns_[i][shell] * length;
  }

 private:
  const ShellMajorants& shells_;
  std::array<const double*, kWavelengthsPerPath> columns_;
};

}  // namespace skyfarm

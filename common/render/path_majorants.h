// One path's majorants, shell by shell: sigma_maj at the path's
// kWavelengthsPerPath wavelengths for every shell of a ShellMajorants,
// gathered once per path.
//
// Why: the table is shell-major over all wavelength bins (51 shells x ~470
// bins for the Earth), so every shell a ray crosses read four doubles from
// four cache lines far apart; a path crosses hundreds of shells (camera ray,
// bounces, a shadow ray per collision).  The path's own rows (32 bytes a
// shell) stay in L1.  The values are the table's, copied: same bits.
//
// Up to kMaxShells rows are gathered (the Earth's fine shells are 51, the
// coarse ones 9); a set of shells with more (an atmosphere reaching far up)
// is read from the table as before.
#pragma once
#include <array>
#include <cstddef>

#include "common/render/atmosphere_medium.h"

namespace skyfarm {

class PathMajorants {
 public:
  static constexpr std::size_t kMaxShells = 64;

  PathMajorants(const ShellMajorants& shells, const std::array<std::size_t, kWavelengthsPerPath>& bins)
      : shells_(shells), bins_(bins), gathered_(shells.shell_count() <= kMaxShells) {
    if (!gathered_) return;
    for (std::size_t k = 0; k < shells.shell_count(); ++k) {
      const double* row = shells.table.data() + k * shells.bins;
      for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) rows_[k][i] = row[bins[i]];
    }
  }

  const ShellMajorants& shells() const { return shells_; }

  SampledSpectrum sigma_maj(std::size_t shell) const {
    if (!gathered_) return shells_.sigma_maj(shell, bins_);
    SampledSpectrum m;
    for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) m.v[i] = rows_[shell][i];
    return m;
  }

 private:
  const ShellMajorants& shells_;
  std::array<std::size_t, kWavelengthsPerPath> bins_;
  bool gathered_;
  std::array<std::array<double, kWavelengthsPerPath>, kMaxShells> rows_;  // left uninitialised past the shells
};

// The table itself at the path's bins, for callers without gathered rows.
struct TableMajorants {
  const ShellMajorants& table;
  const std::array<std::size_t, kWavelengthsPerPath>& bins;
  const ShellMajorants& shells() const { return table; }
  SampledSpectrum sigma_maj(std::size_t shell) const { return table.sigma_maj(shell, bins); }
};

}  // namespace skyfarm

// Distances along a ray drawn inside a set of intervals (the parts of a
// segment the sun reaches: sunlit_intervals.h) as free-flight sampling
// would draw them, but truncated to the set:
//   pdf_i(t) = sigma_maj,i(t) exp(-tau_i(t)) / (1 - exp(-tau_i)),
// tau_i(t) the majorant optical depth of the set before t at wavelength i,
// tau_i that of the whole set.  Samples follow the hero (i = 0); pdf()
// gives every wavelength's pdf for the spectral-MIS ratios.
//
//   ray, set        the ray and its intervals (in order along the ray)
//   R               planet radius (m)
//   shells, bins    the majorant shells and the path's wavelength bins
#pragma once
#include <array>

#include "common/render/atmosphere_medium.h"
#include "common/render/path_majorants.h"
#include "common/render/recorded_shell_walk.h"
#include "common/render/sunlit_intervals.h"

namespace skyfarm {

class LitDistanceSampler {
 public:
  LitDistanceSampler(const Ray& ray, const SunlitIntervals& set, double R, const ShellMajorants& shells,
                     const std::array<std::size_t, kWavelengthsPerPath>& bins);

  // The majorant optical depth of the whole set, per wavelength.
  const SampledSpectrum& tau() const { return tau_; }
  bool empty() const { return !(tau_[0] > 0.0); }
  // The hero's sample for u in [0, 1); false if the set is empty.
  bool sample(double u, double* t) const;
  // Every wavelength's pdf of t (0 outside the set).
  SampledSpectrum pdf(double t) const;

 private:
  PathMajorants majorants_;  // the path's bins of the shells
  std::array<RecordedShellWalk, 2> walks_;  // the first count_ are recorded
  int count_ = 0;
  SampledSpectrum tau_{0.0};
};

}  // namespace skyfarm

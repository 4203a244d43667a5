// The spectral bins of the LUT renderer, and the colour of a binned spectrum.
//
// Parameters
//   lambda_min_nm, lambda_max_nm   the range the bins cover, nm (min < max)
//   bins                           N >= 1 bins of equal width
//                                  w = (max - min) / N; bin i is
//                                  [min + i w, min + (i + 1) w], centre
//                                  lambda_i = min + (i + 1/2) w
//
// A binned spectrum is N values, one per bin.  The tables evaluate the
// atmosphere's coefficients at the bin centres and the sun's irradiance as
// its mean over each bin (bin_mean), so the value of bin i is the radiance at
// lambda_i of a sun whose spectrum is smoothed over the bin width.  For
// colour, the spectrum is REconstructed as the piecewise-linear function
// through (lambda_i, L_i), held constant from the first centre down to
// lambda_min and from the last centre up to lambda_max (and beyond).
//
// BinnedSpectrumIntegral precomputes, for a sub-range [lo, hi], the weights
// that turn such a spectrum into
//   absolute XYZ   (X, Y, Z) = K_m int_lo^hi (xbar, ybar, zbar)(lambda) L(lambda) dlambda,
//                  K_m = 683 lm/W (color.h: the scale of spectral_sample_to_xyz
//                  and spectrum_to_xyz; Y in cd/m^2 for L in W m^-2 sr^-1 nm^-1),
//   band mean      (1 / (hi - lo)) int_lo^hi L(lambda) dlambda,
// so that applying them is a dot product.  The CIE functions are linear
// between their 1 nm knots and the reconstruction is linear between bin
// centres, so Simpson's rule on the merged knots makes the weights exact.
#pragma once
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "common/spectrum/color.h"

namespace skyfarm {

// The LUT sky's default bin count (LutResolution::spectral_bins): the LUT
// builders' passes over the bins are compiled for it as a constant too.
inline constexpr std::size_t kDefaultLutBins = 32;

class SpectralGrid {
 public:
  SpectralGrid() = default;
  // Throws std::invalid_argument for bins < 1 or a range that is not
  // finite, positive and increasing.
  SpectralGrid(double lambda_min_nm, double lambda_max_nm, int bins);

  int size() const { return static_cast<int>(centres_.size()); }
  double lambda_min_nm() const { return lambda_min_; }
  double lambda_max_nm() const { return lambda_max_; }
  double width_nm() const { return width_; }
  double centre_nm(int i) const { return centres_[static_cast<std::size_t>(i)]; }
  std::span<const double> centres_nm() const { return centres_; }

  // Mean of f over bin i, (1/w) int f dlambda, by the trapezoid rule on a
  // 0.25 nm grid aligned to whole nanometres (exact for piecewise-linear
  // tables with knots on that grid, such as the 1 nm AM0 and CIE tables).
  double bin_mean(const std::function<double(double)>& f, int i) const;

  // The reconstruction of a binned spectrum at a wavelength (see above).
  double reconstruct(std::span<const double> values, double lambda_nm) const;

 private:
  double lambda_min_ = 0.0, lambda_max_ = 0.0, width_ = 0.0;
  std::vector<double> centres_;
};

class BinnedSpectrumIntegral {
 public:
  // Weights for the sub-range [lo, hi] (clamped to the grid's range;
  // lo < hi required, else std::invalid_argument).
  BinnedSpectrumIntegral(const SpectralGrid& grid, double lo_nm, double hi_nm);

  // Absolute XYZ of the reconstructed spectrum over [lo, hi].
  Xyz xyz(std::span<const double> values) const;
  // (1 / (hi - lo)) int_lo^hi L dlambda.
  double band_mean(std::span<const double> values) const;

  std::span<const double> x_weights() const { return wx_; }
  std::span<const double> y_weights() const { return wy_; }
  std::span<const double> z_weights() const { return wz_; }
  std::span<const double> mean_weights() const { return wmean_; }

 private:
  std::vector<double> wx_, wy_, wz_, wmean_;
};

}  // namespace skyfarm

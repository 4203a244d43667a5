// The setting of Bruneton's clear-sky evaluation ("A Qualitative and
// Quantitative Evaluation of 8 Clear Sky Models", E. Bruneton, IEEE TVCG
// 2017; code: github.com/ebruneton/clear-sky-models), which scores sky models
// against the sky scans Kider et al. measured on the roof of Cornell's Rhodes
// Hall, Ithaca NY, on 2013-05-27 ("A Framework for the Experimental
// Comparison of Solar and Skydome Illumination", Kider et al., ACM TOG 2014).
// `skyfarm-worker bench sky-accuracy` (bench_sky_accuracy.h) replays it with
// the project's converged path tracer standing in for the measurements.
//
// Everything here is a pure function of the evaluation's definition:
//   cases        17 scans, 09:30-13:30 EDT (UTC-4) every 15 minutes
//                (main.cc: minutes = 9 * 60 + 30 + i * 15, hours + 4 = UTC)
//   place        latitude 42.44337, longitude -76.48163 (main.cc), sky seen
//                from the ground (every model there is asked at altitude 0)
//   directions   the scanner's 81 directions: the centres of a 9 x 9 grid
//                on the unit square, mapped to the unit disk by Shirley and
//                Chiu's concentric map ("A Low Distortion Map Between Disk
//                and Square", 1997) and lifted to the hemisphere with
//                cos(zenith) = 1 - r^2 (atmosphere/hemispherical_function.h,
//                GetSampleDirection); azimuth clockwise from north, as
//                measured_atmosphere.cc turns Kider's counterclockwise file
//                names into.  Rings at elevations 90, 71.92, 53.37, 33.75,
//                12.12 deg with 1, 8, 16, 24, 32 directions.
//   wavelengths  the samples of his spectra (40 from 360 nm in steps of
//                (830 - 360) / 40 = 11.75 nm, physics/units.h and
//                dimensional_types' ScalarFunction::GetSample) that lie in
//                the compared range 360-720 nm: 360 + 11.75 k, k = 0..30
//   score        per case, the root mean square of model - measurement over
//                every direction and every wavelength (comparisons.cc,
//                ComputeRelativeErrorAndRmse: one sum over the 81 x 31
//                values, divided by their count); over the cases, the root
//                mean square of the per-case scores (ComputeTotalRmse).
//                Units W m^-2 sr^-1 nm^-1; the paper quotes mW.
#pragma once
#include <string>
#include <vector>

#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

inline constexpr int kBrunetonCaseCount = 17;
inline constexpr int kBrunetonDirectionCount = 81;
inline constexpr int kBrunetonWavelengthCount = 31;
// Bruneton 2008 ("Precomputed Atmospheric Scattering"), the best of the 8
// models in the paper: its total RMSE against the measurements, mW.
inline constexpr double kBruneton2008TotalRmse_mW = 3.07;

struct BrunetonCase {
  int index = 0;            // 0..16
  std::string local_time;   // "09:30" .. "13:30", EDT
  UtcInstant time;          // local time + 4 h
};

struct BrunetonDirection {
  double zenith_deg = 0.0;   // 0 = straight up
  double azimuth_deg = 0.0;  // clockwise from north, [0, 360)
};

// The place of the scans (altitude 0: the models' ground).
Location bruneton_location();
// The 17 cases in time order.
std::vector<BrunetonCase> bruneton_cases();
// The 81 directions in Bruneton's loop order: grid cell (i, j), i outer.
std::vector<BrunetonDirection> bruneton_directions();
// The 31 wavelengths, nm, increasing.
std::vector<double> bruneton_wavelengths_nm();

// Per-case score: sqrt(sum over [d][w] of (model - reference)^2 / count).
// Both arrays [direction][wavelength] of the same shape; throws
// std::invalid_argument otherwise or when empty.
double bruneton_case_rmse(const std::vector<std::vector<double>>& model,
                          const std::vector<std::vector<double>>& reference);
// Total score: sqrt(mean of the per-case scores squared).  Throws
// std::invalid_argument when empty.
double bruneton_total_rmse(const std::vector<double>& case_rmse);

}  // namespace skyfarm

// skyfarm-worker bench efficiency [--samples N] [--sun-zenith Z ...]
// [--shadow-scale S] [--sunlit-segments]: the integrator's efficiency
// 1/(relative variance per path x seconds per path) over the whole sky at
// 550 nm, for comparing estimators and options.
//
// For each sun zenith angle (default 30, 85, 96 deg; sun at azimuth 180),
// N paths (default 1000) in each of 36 x 24 directions (zenith 2.5..177.5
// every 5 deg, azimuth 7.5..352.5 every 15 deg, the sun's disk left out),
// one thread: the luminance-weighted relative standard deviation per path
// sqrt(sum_d w_d var_d / sum_d w_d L_d^2), w_d = sin(zenith) (solid angle),
// the mean time per path, and their efficiency.  One JSON line per sun.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_efficiency(const std::vector<std::string>& args);

}  // namespace skyfarm

// How far a render has come towards the first of its limits (the quality
// modes: samples, target error, time limit), for progress bars and
// ETAs.  A request that stops by a target error or a time limit alone has
// no sample cap (1048576 samples per pixel), so the share of its samples
// done says nothing: a 512x256 frame asked for "1 % in at most 2 minutes"
// read 0.02 % done and 250 000 s to go when it was 80 s from its target.
//
//   progress = max( samples done / samples asked,
//                   elapsed / time limit,
//                   (target error / estimated error)^2 )      in [0, 1]
//
// The last term is the share of the work the target needs if the error
// falls as 1 / sqrt(samples) (the Monte Carlo rate that bench convergence
// measures: slopes -0.47 to -0.52 except at twilight).
#pragma once
#include <optional>

namespace skyfarm {

double render_progress(double samples_share, double elapsed_s, std::optional<double> time_limit_s,
                       std::optional<double> target_relative_error, std::optional<double> estimated_relative_rms);

// Seconds left at this progress after `elapsed_s` (nullopt before any progress).
std::optional<double> remaining_seconds(double progress, double elapsed_s);

}  // namespace skyfarm

// skyfarm-worker bench convergence [--out DIR] [--passes N]: error against
// run time.  For each scene (noon, sun at 85 deg,
// sunset, twilight at 96 deg, a view from 400 km, haze AOD 0.5, a Paris
// afternoon clear and with scattered cumulus): a converged
// reference rendered once and cached in DIR, then a render whose true
// relative RMS error against the reference (luminance-weighted) and whose own
// estimate are recorded after every whole pass; a CSV per scene
// (scripts/plot-figures.py draws it, log-log, beside it as a PNG), and one
// JSON line with the fitted slope of log(error) against log(time) (-1/2 for a
// sound Monte Carlo estimator) and the worst ratio of estimate to truth.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_convergence(const std::vector<std::string>& args);

}  // namespace skyfarm

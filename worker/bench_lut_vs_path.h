// skyfarm-worker bench lut-vs-path [--out DIR] [--spp N]: the LUT renderer's
// error against converged path-traced references.
//
// Cases: sun zenith 0, 30, 60, 80, 85, 90, 93, 96 deg (azimuth 180) x
// observer altitude 0, 10 km, 100 km, Earth preset.  Each renders a 36 x 18
// equirect (10 deg pixels, centred on the sun's azimuth, so mirror-symmetric)
// with 8 wavelength batches over 360-830 nm, by the LUT and by the path
// tracer (N spp, default 2048; cached in DIR as raw floats, so a rerun only
// renders the LUT).  Per case, over the pixels that do not see the sun disk
// and weighted by solid angle:
//   luminance   relative RMS error sqrt(sum w (Y_lut - Y)^2 / sum w Y^2) and
//               the largest relative error |Y_lut - Y| / Y over pixels with
//               Y > 1e-3 max Y, with the direction where it occurs;
//   per batch   relative RMS error of the band-mean spectral radiance;
//   reference   the path tracer's own estimated relative RMS error (the
//               comparison cannot resolve errors below it).
// Writes DIR/lut_vs_path.csv (scripts/plot-figures.py draws it beside it as
// a PNG: luminance relative RMS error against sun zenith, one line per
// altitude, and the references' own error) and one JSON line per case.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_lut_vs_path(const std::vector<std::string>& args);

}  // namespace skyfarm

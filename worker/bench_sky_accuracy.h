// skyfarm-worker bench sky-accuracy [--reference FILE] [--out DIR]
//     [--cases N] [--threads N] [--repeat N] [--reference-samples N]:
// Bruneton's 2017 clear-sky evaluation (worker/bruneton_evaluation.h)
// replayed with the converged path tracer as the truth instead of Kider's
// measurements, on Bruneton's demo atmosphere
// (api/examples/probe_bruneton_2017.json, embedded: its location, sun,
// atmosphere, directions and wavelengths).
//
// Truth: the path-traced probe (answer_probe, the machinery of
// `skyfarm-worker probe`) of each case at --reference-samples samples per
// direction and wavelength (default 8192) with seed 2017, so it shares no
// random numbers with the scored path tracer (seed 1); or read from FILE, a
// reference CSV this bench wrote.  Its noise, the RMS of its standard errors,
// is stated per direction (the CSV) and per case: the score a perfect model
// would get against it.
//
// Scored, per case, by Bruneton's RMSE over 81 directions x 31 wavelengths:
//   lut    the probe's "lut" method (one 1-nm bin per wavelength), CPU time
//          of its table builds and look-ups
//   sky    what GET /v1/sky serves: one table of LutResolution{} (32 bins
//          over 360-830 nm, the sky service's default), read at each
//          wavelength by linear interpolation between bin centres, CPU time
//          of the build and look-ups
//   path   the probe's "path" method at its default quality (4096 samples),
//          seed 1, CPU and wall time on --threads threads (0: all cores)
// with the median |error| and the largest |error| beside each RMSE.  The
// LUT timings are the median of --repeat runs (default 3); the path tracer
// runs once (its answer does not change, only its time).
//
// Writes DIR/sky_accuracy.csv (one row per case), DIR/sky_accuracy.md (the
// table and the totals, as in the README) and DIR/sky_accuracy_reference.csv
// (the truth, mW, 5 significant digits, one row per case and direction with
// the RMS of its standard errors), and one JSON line per case on stdout.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_sky_accuracy(const std::vector<std::string>& args);

}  // namespace skyfarm

// skyfarm-worker bench lut-clouds [--out DIR] [--spp N] [options]: the LUT renderer's
// clouds (common/lut/cloud_march.h) against path-traced references of the
// same scenes.
//
// Scenes (Earth preset, sun azimuth 180, 360-830 nm, one batch):
//   slab      a uniform overcast shell 1-2 km, vertical tau 8, cloud optics
//             of water droplets r_eff 10 um (cloud_optics.h)
//   cumulus   the cumulus preset layer (cloud_layer_preset; skipped, with
//             its reason, where this build cannot make it)
// each seen from the ground (cloud bases, clear gaps) and from 4 km (cloud
// tops), sun at 40 and 70 deg.  Frame: 72 x 36 equirect (5 deg pixels, yaw
// 180), the path tracer at N spp (default 256; cached in DIR as raw floats,
// so a rerun only renders the LUT).  Regions, by the LUT march's cloud
// transmittance T_c along each pixel's centre: cloud (T_c < 0.5; bases from
// below, tops from above), gap (T_c > 0.95, above the horizon, seen from
// below), and the whole frame; the sun's pixels (within 10 deg) are left
// out.  Per region, weighted by solid angle: the relative error of the mean
// luminance, mean(Y_lut) / mean(Y_path) - 1, the median over the pixels of
// Y_lut / Y_path - 1 (robust to the reference's rare bright outliers, which
// clouds make common at a few hundred spp), and the path tracer's own
// estimated relative error of the mean.
// --octaves N, --octave-abc A B C, --octaves-only and --no-ambient set the LUT's cloud
// march options (cloud_march.h; defaults otherwise) to compare variants.
// Writes DIR/lut_clouds.csv and one JSON line per case.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_lut_clouds(const std::vector<std::string>& args);

}  // namespace skyfarm

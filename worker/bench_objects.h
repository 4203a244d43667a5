// skyfarm-worker bench objects [paths|mirror|all] [--repeat N] [--passes P]
// [--seeds K] [--reference-passes R]: what objects cost and how a mirror
// ball converges.
//
// paths   paths per second on one thread, the reference balls (a mirror,
//         a grey 0.18 and a white 0.8 ball of 0.5 m on grass, 5 m ahead of
//         a camera 1.6 m up, noon sun at zenith 30 deg behind it) against
//         the same view without them: the wide view (96x54, fov 55, 8 spp,
//         a tenth of the pixels on a ball) and the mirror-ball close-up
//         (64x64, fov 15, 8 spp, half of them on it).  N runs each
//         (default 5), medians of paths per CPU second of the process
//         ("median", the rendering thread's work whatever else runs) and
//         per wall second ("median_wall").  One JSON line per view and scene.
// mirror  the close-up's error against time: a reference of R passes
//         (default 256, 16 spp each; all threads, another seed), then K
//         renders of P passes (default 3 and 32) with seeds 1..K; after
//         passes 1, 2, 4, ... the relative RMS error of luminance over the
//         pixels wholly on the chrome ball, sqrt(sum (Y - Y_ref)^2 /
//         sum Y_ref^2), and the elapsed time, medians over the seeds.  The
//         pixels that may reflect the sun (the disk within the spread of
//         their corners' reflections) are left out, as the disk is from
//         the renderer's own estimate: a few pixels 1e5 x the sky, hit or
//         missed by chance, would be the whole error.
//         One JSON line per pass count, then the fitted slope of log error
//         against log time (-1/2 for an unbiased estimator).
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_objects(const std::vector<std::string>& args);

}  // namespace skyfarm

// skyfarm-worker bench [paths|demo|memory|all] [--repeat N]: the renderer's
// benchmarks (not tests).  Each prints its figures as JSON lines.
//   paths   camera paths per second per core (one thread), noon ground-level
//           equirectangular and sunset, 4 wavelengths per path; median of N
//   demo    wall time of the README's demo renders on all cores; median of N
//   memory  peak resident memory of a 4096x2048 equirectangular render (1 spp)
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_bench_command(const std::vector<std::string>& args);

}  // namespace skyfarm

// skyfarm-worker render REQUEST.json -o OUT.exr [--png OUT.png] [--threads N]
// and skyfarm-worker probe PROBE.json|- [--threads N].
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

int run_render_command(const std::vector<std::string>& args);
// skyfarm-worker demo [DIR]: the README's demo skies to DIR/*.exr and *.png.
int run_demo_command(const std::vector<std::string>& args);
int run_probe_command(const std::vector<std::string>& args);

}  // namespace skyfarm

// The demo skies of the README's run command: a sunset over Ithaca as an
// equirectangular environment map and a noon all-sky fisheye over Paris.
#pragma once
#include <string>
#include <vector>

namespace skyfarm {

struct DemoRequest {
  std::string name;  // output file stem
  std::string json;  // a render request
};

const std::vector<DemoRequest>& demo_requests();

}  // namespace skyfarm

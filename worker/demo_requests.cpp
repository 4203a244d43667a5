#include "worker/demo_requests.h"

namespace skyfarm {

const std::vector<DemoRequest>& demo_requests() {
  static const std::vector<DemoRequest> demos = {
      {"sunset_equirect", R"({
        "location": {"latitude_deg": 42.44, "longitude_deg": -76.48, "altitude_m": 250},
        "time": "2013-05-27T20:15:00-04:00",
        "camera": {"projection": "equirectangular", "width": 512, "height": 256, "yaw_deg": 300},
        "spectral": {"batches": 2},
        "quality": {"samples_per_pixel": 32},
        "output": {"half": false}})"},
      {"noon_fisheye", R"({
        "location": {"latitude_deg": 48.8566, "longitude_deg": 2.3522, "altitude_m": 35},
        "time": "2021-06-21T13:50:00+02:00",
        "camera": {"projection": "fisheye", "width": 256, "height": 256, "yaw_deg": 180, "pitch_deg": 90,
                   "fov_deg": 180},
        "spectral": {"batches": 2},
        "quality": {"samples_per_pixel": 32},
        "output": {"half": false}})"},
  };
  return demos;
}

}  // namespace skyfarm

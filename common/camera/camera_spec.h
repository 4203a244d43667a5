// "camera" of a render request.  Plain data, validated by api/.
#pragma once

namespace skyfarm {

enum class Projection { kEquirectangular, kFisheye, kPerspective };

struct CameraSpec {
  Projection projection = Projection::kEquirectangular;
  int width = 1024;
  int height = 512;
  double yaw_deg = 0.0;    // azimuth of the view centre, clockwise from north
  double pitch_deg = 0.0;  // elevation of the view centre above the horizon
  double roll_deg = 0.0;   // rotation about the view axis
  double fov_deg = 60.0;   // perspective: horizontal field of view; fisheye: full angle
};

}  // namespace skyfarm

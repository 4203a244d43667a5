#include "common/geometry/enu_frame.h"

#include <cmath>
#include <stdexcept>

#include "common/geometry/rounding_error.h"

namespace skyfarm {

EnuFrame::EnuFrame(double observer_radius_m) : z0_(observer_radius_m) {
  if (!(observer_radius_m > 0.0) || !std::isfinite(observer_radius_m))
    throw std::invalid_argument("enu frame: observer radius must be positive and finite");
}

ShapeHit EnuFrame::to_world(const ShapeHit& h) const {
  ShapeHit out = h;
  out.p = to_world(h.p);
  // Only z is translated; its sum rounds by at most u |z|, and the error it
  // carried stays (times 1 + u for the bound's own rounding).
  out.p_error.z = (1.0 + rounding_gamma(1)) * h.p_error.z + rounding_gamma(1) * std::abs(out.p.z);
  return out;
}

}  // namespace skyfarm

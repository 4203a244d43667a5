#include "common/clouds/cloud_profile.h"

#include <stdexcept>
#include <string>

namespace skyfarm {

namespace {
// The cubic smoothstep on [0, 1]: monotone, C1, and its integral over [0, 1]
// is 1/2 (by the symmetry s(x) + s(1 - x) = 1).
double smoothstep01(double s) { return s * s * (3.0 - 2.0 * s); }
}  // namespace

CloudProfile::CloudProfile(double rise_end, double fall_begin) : rise_end_(rise_end), fall_begin_(fall_begin) {
  if (!(rise_end > 0.0 && rise_end <= fall_begin && fall_begin < 1.0))
    throw std::invalid_argument("cloud profile: need 0 < rise_end <= fall_begin < 1, got " +
                                std::to_string(rise_end) + ", " + std::to_string(fall_begin));
}

// The shapes follow Schneider (2017)'s density-height gradients per genus,
// reduced to their edges: where the layer's cloud starts being full and where
// it starts thinning towards the top.
CloudProfile CloudProfile::for_type(CloudType type) {
  switch (type) {
    case CloudType::kCumulus: return {0.08, 0.35};
    case CloudType::kStratocumulus: return {0.2, 0.55};
    case CloudType::kStratus: return {0.1, 0.9};
    case CloudType::kCirrus: return {0.25, 0.4};
    case CloudType::kCustom: return {0.05, 0.95};
  }
  return {0.05, 0.95};
}

double CloudProfile::operator()(double x) const {
  if (!(x > 0.0 && x < 1.0)) return 0.0;  // NaN too
  if (x < rise_end_) return smoothstep01(x / rise_end_);
  if (x <= fall_begin_) return 1.0;
  return 1.0 - smoothstep01((x - fall_begin_) / (1.0 - fall_begin_));
}

double CloudProfile::max_over(double x0, double x1) const {
  if (x1 < rise_end_) return (*this)(x1);   // all on the rising side
  if (x0 > fall_begin_) return (*this)(x0);  // all on the falling side
  return 1.0;                                // meets the plateau
}

}  // namespace skyfarm

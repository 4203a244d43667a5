// The height profile of a cloud layer: the density's share, in [0, 1], at a
// normalised height x = (altitude - base) / thickness in the layer, by type.
//
// Every profile is unimodal, built from two cubic smoothsteps
// (3 s^2 - 2 s^3) around a plateau:
//
//   p(x) = smoothstep(x / rise_end)                     0 <= x < rise_end
//        = 1                                            rise_end <= x <= fall_begin
//        = 1 - smoothstep((x - fall_begin) / (1 - fall_begin))   fall_begin < x <= 1
//
// and 0 outside [0, 1].  Unimodal is what makes the majorants exact and cheap:
// the maximum over [x0, x1] is p at the point of [x0, x1] nearest the plateau.
//
//   cumulus        a quick rise above the flat base, a long fall: rounded tops
//   stratocumulus  a thicker middle, softer base and top
//   stratus        a slab with soft edges
//   cirrus         thin: a short plateau low in the layer, a long fall (fall streaks)
//   custom         a plain box with soft edges (5% each side)
#pragma once
#include "common/clouds/cloud_spec.h"

namespace skyfarm {

class CloudProfile {
 public:
  // Throws std::invalid_argument unless 0 < rise_end <= fall_begin < 1.
  CloudProfile(double rise_end, double fall_begin);
  static CloudProfile for_type(CloudType type);

  double operator()(double x) const;
  // max p over [x0, x1] (x0 <= x1), exactly.
  double max_over(double x0, double x1) const;
  // integral of p over [0, 1], closed form: each smoothstep edge holds half its width.
  double integral() const { return 0.5 * rise_end_ + (fall_begin_ - rise_end_) + 0.5 * (1.0 - fall_begin_); }

  double rise_end() const { return rise_end_; }
  double fall_begin() const { return fall_begin_; }

 private:
  double rise_end_, fall_begin_;
};

}  // namespace skyfarm

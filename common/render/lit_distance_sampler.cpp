#include "common/render/lit_distance_sampler.h"

#include <algorithm>
#include <cmath>

namespace skyfarm {

LitDistanceSampler::LitDistanceSampler(const Ray& ray, const SunlitIntervals& set, double R,
                                       const ShellMajorants& shells,
                                       const std::array<std::size_t, kWavelengthsPerPath>& bins)
    : majorants_(shells, bins), count_(set.count) {
  for (int k = 0; k < count_; ++k) {
    const auto [a, b] = set.lit[static_cast<std::size_t>(k)];
    walks_[static_cast<std::size_t>(k)].record(ShellTraversal(ray, R, shells.bottoms, a, b));
    auto walk = walks_[static_cast<std::size_t>(k)].replay();
    ShellSegment seg;
    while (walk.next(&seg)) tau_ += majorants_.sigma_maj(seg.shell) * (seg.t1 - seg.t0);
  }
}

// Inversion: the point where the hero's majorant optical depth of the set
// reaches tau* = -ln(1 - u (1 - e^-tau)), the truncated exponential.
bool LitDistanceSampler::sample(double u, double* t) const {
  if (empty()) return false;
  const double mass = -std::expm1(-tau_[0]);
  double target = std::min(tau_[0], -std::log1p(-u * mass));
  for (int k = 0; k < count_; ++k) {
    auto walk = walks_[static_cast<std::size_t>(k)].replay();
    ShellSegment seg;
    while (walk.next(&seg)) {
      const double m = majorants_.sigma_maj(seg.shell)[0];
      const double tau_seg = m * (seg.t1 - seg.t0);
      if (m > 0.0 && target <= tau_seg) {
        *t = seg.t0 + target / m;
        return true;
      }
      target -= tau_seg;
    }
  }
  return false;
}

SampledSpectrum LitDistanceSampler::pdf(double t) const {
  SampledSpectrum tau_t(0.0);
  for (int k = 0; k < count_; ++k) {
    auto walk = walks_[static_cast<std::size_t>(k)].replay();
    ShellSegment seg;
    while (walk.next(&seg)) {
      const SampledSpectrum m = majorants_.sigma_maj(seg.shell);
      if (t >= seg.t0 && t <= seg.t1) {
        tau_t += m * (t - seg.t0);
        SampledSpectrum p;
        for (int i = 0; i < kWavelengthsPerPath; ++i)
          p[i] = tau_[i] > 0.0 ? m[i] * std::exp(-tau_t[i]) / -std::expm1(-tau_[i]) : 0.0;
        return p;
      }
      tau_t += m * (seg.t1 - seg.t0);
    }
  }
  return SampledSpectrum(0.0);
}

}  // namespace skyfarm

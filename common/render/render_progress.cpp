#include "common/render/render_progress.h"

#include <algorithm>
#include <cmath>

namespace skyfarm {

double render_progress(double samples_share, double elapsed_s, std::optional<double> time_limit_s,
                       std::optional<double> target_relative_error, std::optional<double> estimated_relative_rms) {
  double p = std::isfinite(samples_share) ? samples_share : 0.0;
  if (time_limit_s && *time_limit_s > 0.0 && std::isfinite(elapsed_s)) p = std::max(p, elapsed_s / *time_limit_s);
  if (target_relative_error && estimated_relative_rms && *estimated_relative_rms > 0.0) {
    const double r = *target_relative_error / *estimated_relative_rms;
    if (std::isfinite(r)) p = std::max(p, r * r);
  }
  return std::clamp(p, 0.0, 1.0);
}

std::optional<double> remaining_seconds(double progress, double elapsed_s) {
  if (!(progress > 0.0) || !std::isfinite(elapsed_s)) return std::nullopt;
  return std::max(0.0, elapsed_s * (1.0 - progress) / progress);
}

}  // namespace skyfarm

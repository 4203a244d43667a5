#include "common/core/metrics_histogram.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skyfarm {
namespace {

std::vector<double> checked_bounds(std::span<const double> bounds) {
  if (bounds.empty()) throw std::invalid_argument("MetricsHistogram: no bucket bounds");
  for (std::size_t i = 0; i < bounds.size(); ++i) {
    if (!std::isfinite(bounds[i])) throw std::invalid_argument("MetricsHistogram: a bucket bound is not finite");
    if (i > 0 && !(bounds[i - 1] < bounds[i]))
      throw std::invalid_argument("MetricsHistogram: bucket bounds must strictly increase");
  }
  return {bounds.begin(), bounds.end()};
}

}  // namespace

MetricsHistogram::MetricsHistogram(std::span<const double> upper_bounds)
    : bounds_(checked_bounds(upper_bounds)), counts_(bounds_.size() + 1, 0) {}

MetricsHistogram::MetricsHistogram(const MetricsHistogram& other) : bounds_(other.bounds_) {
  const std::lock_guard lock(other.mu_);
  counts_ = other.counts_;
  sum_ = other.sum_;
  count_ = other.count_;
}

void MetricsHistogram::observe(double value) {
  // The first bound >= value (le is inclusive); NaN compares false everywhere
  // and lands past the end, in +Inf.
  const auto it = std::find_if(bounds_.begin(), bounds_.end(), [value](double b) { return value <= b; });
  const auto bucket = static_cast<std::size_t>(it - bounds_.begin());
  const std::lock_guard lock(mu_);
  ++counts_[bucket];
  sum_ += value;
  ++count_;
}

MetricsHistogram::Snapshot MetricsHistogram::snapshot() const {
  Snapshot s;
  s.upper_bounds = bounds_;
  s.cumulative.resize(counts_.size());
  const std::lock_guard lock(mu_);
  std::uint64_t running = 0;
  for (std::size_t i = 0; i < counts_.size(); ++i) s.cumulative[i] = running += counts_[i];
  s.sum = sum_;
  s.count = count_;
  return s;
}

}  // namespace skyfarm

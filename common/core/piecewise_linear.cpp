#include "common/core/piecewise_linear.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace skyfarm {

PiecewiseLinear::PiecewiseLinear(std::vector<double> x, std::vector<double> y, Outside outside,
                                 const std::string& what)
    : x_(std::move(x)), y_(std::move(y)), outside_(outside) {
  if (x_.empty()) throw std::invalid_argument(what + ": needs at least one point");
  if (x_.size() != y_.size())
    throw std::invalid_argument(what + ": " + std::to_string(x_.size()) + " abscissae but " +
                                std::to_string(y_.size()) + " values");
  for (std::size_t i = 0; i < x_.size(); ++i) {
    if (!std::isfinite(x_[i]) || !std::isfinite(y_[i]))
      throw std::invalid_argument(what + ": non-finite entry at index " + std::to_string(i));
    if (i > 0 && !(x_[i] > x_[i - 1]))
      throw std::invalid_argument(what + ": abscissae must increase strictly (index " + std::to_string(i) + ")");
  }
  build_buckets();
}

void PiecewiseLinear::build_buckets() {
  constexpr std::size_t kMinKnots = 16, kMaxBuckets = std::size_t{1} << 16;
  const std::size_t n = x_.size();
  if (n < kMinKnots) return;
  std::vector<double> steps(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) steps[i] = x_[i + 1] - x_[i];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  // The longest run of intervals no wider than 4 medians.
  std::size_t best_lo = 0, best_hi = 0;
  for (std::size_t lo = 0; lo < n - 1;) {
    if (steps[lo] > 4.0 * median) {
      ++lo;
      continue;
    }
    std::size_t hi = lo;
    while (hi < n - 1 && steps[hi] <= 4.0 * median) ++hi;
    if (hi - lo > best_hi - best_lo) {
      best_lo = lo;
      best_hi = hi;
    }
    lo = hi;
  }
  if (best_hi - best_lo + 1 < kMinKnots) return;
  window_lo_ = x_[best_lo];
  window_hi_ = x_[best_hi];
  const double width = window_hi_ - window_lo_;
  const std::size_t buckets = std::min(kMaxBuckets, static_cast<std::size_t>(std::ceil(width / median)) + 1);
  bucket_scale_ = static_cast<double>(buckets) / width;
  bucket_knot_.resize(buckets);
  for (std::size_t j = 0; j < buckets; ++j) {
    const double edge = window_lo_ + static_cast<double>(j) / bucket_scale_;
    const auto it = std::upper_bound(x_.begin(), x_.end(), edge);
    bucket_knot_[j] = static_cast<std::uint32_t>(std::max<std::ptrdiff_t>(it - x_.begin() - 1, 0));
  }
}

std::size_t PiecewiseLinear::first_knot_above(double x) const {
  const std::size_t n = x_.size();
  if (x >= window_lo_ && x < window_hi_ && !bucket_knot_.empty()) {
    auto j = static_cast<std::size_t>((x - window_lo_) * bucket_scale_);
    if (j >= bucket_knot_.size()) j = bucket_knot_.size() - 1;
    std::size_t i = bucket_knot_[j];
    while (i < n && x_[i] <= x) ++i;
    // x_[i] > x by the loop; i is the first such knot when x_[i - 1] <= x.
    if (i > 0 && i < n && x_[i - 1] <= x) return i;
  }
  return static_cast<std::size_t>(std::upper_bound(x_.begin(), x_.end(), x) - x_.begin());
}

PiecewiseLinear PiecewiseLinear::constant(double value) { return PiecewiseLinear({0.0}, {value}); }

PiecewiseLinear::Location PiecewiseLinear::locate(double x) const {
  Location at;
  at.x = x;
  if (x_.size() == 1) {
    at.kind = Location::Kind::kSingle;
  } else if (x <= x_.front()) {
    at.kind = Location::Kind::kAtOrBelowFront;
  } else if (x >= x_.back()) {
    at.kind = Location::Kind::kAtOrAboveBack;
  } else {
    // First knot strictly greater than x: x lies in [x_[i-1], x_[i]).
    at.kind = Location::Kind::kInside;
    at.i = first_knot_above(x);
    at.t = (x - x_[at.i - 1]) / (x_[at.i] - x_[at.i - 1]);
  }
  return at;
}

double PiecewiseLinear::eval(double x) const { return eval_at(locate(x)); }

double PiecewiseLinear::eval_at(const Location& at) const {
  const double x = at.x;
  switch (at.kind) {
    case Location::Kind::kSingle:
      return (outside_ == Outside::kZero && x != x_[0]) ? 0.0 : y_[0];
    case Location::Kind::kAtOrBelowFront:
      return (x < x_.front() && outside_ == Outside::kZero) ? 0.0 : y_.front();
    case Location::Kind::kAtOrAboveBack:
      return (x > x_.back() && outside_ == Outside::kZero) ? 0.0 : y_.back();
    case Location::Kind::kInside:
      break;
  }
  return y_[at.i - 1] + at.t * (y_[at.i] - y_[at.i - 1]);
}

template <class Reduce>
double PiecewiseLinear::extreme_on(double a, double b, Reduce reduce) const {
  double m = reduce(eval(a), eval(b));
  // Outside the knots with kZero the function jumps to 0 next to the end
  // values: include 0 when [a, b] reaches outside.
  if (outside_ == Outside::kZero && (a < x_.front() || b > x_.back())) m = reduce(m, 0.0);
  auto lo = std::upper_bound(x_.begin(), x_.end(), a);
  for (auto it = lo; it != x_.end() && *it < b; ++it)
    m = reduce(m, y_[static_cast<std::size_t>(it - x_.begin())]);
  return m;
}

double PiecewiseLinear::max_on(double a, double b) const {
  return extreme_on(a, b, [](double p, double q) { return std::max(p, q); });
}

double PiecewiseLinear::min_on(double a, double b) const {
  return extreme_on(a, b, [](double p, double q) { return std::min(p, q); });
}

double PiecewiseLinear::integral(double a, double b) const {
  if (b < a) return -integral(b, a);
  // Integrate segment by segment between consecutive breakpoints in [a, b].
  std::vector<double> points{a};
  for (double xi : x_)
    if (xi > a && xi < b) points.push_back(xi);
  points.push_back(b);
  double sum = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    const double x0 = points[i - 1], x1 = points[i];
    // A kZero table is discontinuous at its ends: evaluate just inside.
    const double mid = 0.5 * (x0 + x1);
    if (outside_ == Outside::kZero && (mid < x_.front() || mid > x_.back())) continue;
    const double y0 = eval(std::clamp(x0, x_.front(), x_.back()));
    const double y1 = eval(std::clamp(x1, x_.front(), x_.back()));
    sum += 0.5 * (y0 + y1) * (x1 - x0);
  }
  return sum;
}

}  // namespace skyfarm

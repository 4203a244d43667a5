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
}

PiecewiseLinear PiecewiseLinear::constant(double value) { return PiecewiseLinear({0.0}, {value}); }

double PiecewiseLinear::eval(double x) const {
  if (x_.size() == 1) return (outside_ == Outside::kZero && x != x_[0]) ? 0.0 : y_[0];
  if (x <= x_.front()) return (x < x_.front() && outside_ == Outside::kZero) ? 0.0 : y_.front();
  if (x >= x_.back()) return (x > x_.back() && outside_ == Outside::kZero) ? 0.0 : y_.back();
  // First knot strictly greater than x: x lies in [x_[i-1], x_[i]).
  const auto it = std::upper_bound(x_.begin(), x_.end(), x);
  const std::size_t i = static_cast<std::size_t>(it - x_.begin());
  const double t = (x - x_[i - 1]) / (x_[i] - x_[i - 1]);
  return y_[i - 1] + t * (y_[i] - y_[i - 1]);
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

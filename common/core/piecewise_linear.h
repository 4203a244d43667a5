// A tabulated function y(x), linear between knots: every spectrum (cross-
// sections, albedo, irradiance) and every tabulated profile is one of these.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace skyfarm {

class PiecewiseLinear {
 public:
  // What eval() returns outside [x.front(), x.back()].
  enum class Outside { kClamp, kZero };

  PiecewiseLinear() = default;
  // x strictly increasing, same size as y, at least one knot; throws
  // std::invalid_argument otherwise (naming `what`).
  PiecewiseLinear(std::vector<double> x, std::vector<double> y, Outside outside = Outside::kClamp,
                  const std::string& what = "table");
  static PiecewiseLinear constant(double value);

  double eval(double x) const;
  double operator()(double x) const { return eval(x); }

  // Where x lies among the knots.  Tables with the same knots (built from
  // one abscissa column, like the CIE matching functions) can all be
  // evaluated at x from one locate() with eval_at(): one search instead of
  // one per table, and the same value as eval(x) for each.
  struct Location {
    enum class Kind { kSingle, kAtOrBelowFront, kAtOrAboveBack, kInside };
    Kind kind = Kind::kSingle;
    double x = 0.0;
    std::size_t i = 0;  // kInside: x lies in [x_[i-1], x_[i])
    double t = 0.0;     // kInside: (x - x_[i-1]) / (x_[i] - x_[i-1])
  };
  Location locate(double x) const;
  // This table's value at a location found by it or by a table with the same knots.
  double eval_at(const Location& at) const;

  // Exact maximum / minimum of the interpolant over [a, b] (a <= b): the
  // extremes of a piecewise-linear function lie at the ends or at knots.
  double max_on(double a, double b) const;
  double min_on(double a, double b) const;
  // Exact integral of the interpolant over [a, b] (trapezoids between knots).
  double integral(double a, double b) const;

  std::span<const double> x() const { return x_; }
  std::span<const double> y() const { return y_; }
  bool empty() const { return x_.empty(); }
  double x_min() const { return x_.front(); }
  double x_max() const { return x_.back(); }

 private:
  template <class Reduce>
  double extreme_on(double a, double b, Reduce reduce) const;
  // The first knot strictly greater than x, for x_.front() < x < x_.back():
  // what std::upper_bound gives, found from the bucket index when x falls in
  // its window (the answer is checked, so it is always upper_bound's).
  std::size_t first_knot_above(double x) const;
  void build_buckets();

  std::vector<double> x_, y_;
  Outside outside_ = Outside::kClamp;
  // Bucket index for eval(): uniform buckets over the longest run of knots
  // spaced at most 4x the median spacing (AM0: 119.5-2500 nm at 1-2 nm,
  // beyond which it thins out to 600 000 nm); bucket j starts at
  // window_lo_ + j / bucket_scale_ and bucket_knot_[j] is the last knot at or
  // before that.  Empty for tables too small to need it.  Path tracing
  // evaluates tables (the CIE functions, the sun, the albedo) at random
  // wavelengths for every path: a binary search there is 10 or 11
  // unpredictable branches.
  double window_lo_ = 0.0, window_hi_ = 0.0, bucket_scale_ = 0.0;
  std::vector<std::uint32_t> bucket_knot_;
};

}  // namespace skyfarm

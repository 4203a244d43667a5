// A tabulated function y(x), linear between knots: every spectrum (cross-
// sections, albedo, irradiance) and every tabulated profile is one of these.
#pragma once
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

  std::vector<double> x_, y_;
  Outside outside_ = Outside::kClamp;
};

}  // namespace skyfarm

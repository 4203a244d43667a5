// Several functions tabulated on one uniform grid x0 + i step, i = 0..n-1,
// each linear between knots and held at its end values outside [x0, x1].
//
// Why one set and not one table per function: the path tracer evaluates all
// of them at the same x (every constituent's density at a collision's
// altitude; every wavelength factor at a path's wavelengths).  The set finds
// x's interval once (locate) and stores the values knot-major (row i holds
// every function's value at knot i), so one evaluation of all the functions
// reads rows i and i + 1: one or two cache lines, where separate tables of
// tens of kilobytes each cost a cache miss apiece.  Each value is computed
// exactly as a single table would (the same position u, the same
// v_i + u (v_{i+1} - v_i)): the same bits.
//
//   x0, x1     grid ends (x0 < x1 when n > 1); the last knot is x1 exactly
//   n          knots, >= 1
//   functions  the tabulated functions, one column each, in this order
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

namespace skyfarm {

class UniformTableSet {
 public:
  // Where x lies: the row at or below it and the fraction u of the step to
  // the next row, or a row to be returned as it is (x outside the grid).
  struct Position {
    const double* row = nullptr;
    double u = 0.0;
    bool held = true;  // outside the grid (or a one-knot grid): row's values
  };

  UniformTableSet() = default;
  UniformTableSet(double x0, double x1, int n, const std::vector<std::function<double(double)>>& functions);

  std::size_t columns() const { return columns_; }

  Position locate(double x) const {
    double u = (x - x0_) * inv_step_;
    if (!(u > 0.0)) return {values_.data(), 0.0, true};
    const double last = static_cast<double>(knots_ - 1);
    if (u >= last) return {values_.data() + (knots_ - 1) * columns_, 0.0, true};
    const auto i = static_cast<std::size_t>(u);
    u -= static_cast<double>(i);
    return {values_.data() + i * columns_, u, false};
  }
  // Function `column` at the located x.
  double eval(const Position& p, std::size_t column) const {
    const double v0 = p.row[column];
    if (p.held) return v0;
    return v0 + p.u * (p.row[columns_ + column] - v0);
  }
  double eval(double x, std::size_t column) const { return eval(locate(x), column); }
  // The smallest value of function `column` on [a, b]: at the ends or at a
  // knot in between (it is linear between knots).
  double min_on(std::size_t column, double a, double b) const;

 private:
  double x0_ = 0.0, inv_step_ = 1.0;
  std::size_t knots_ = 1, columns_ = 0;
  std::vector<double> values_;  // knot-major: values_[i * columns_ + column]
};

}  // namespace skyfarm

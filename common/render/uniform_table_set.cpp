#include "common/render/uniform_table_set.h"

#include <algorithm>
#include <cmath>

namespace skyfarm {

UniformTableSet::UniformTableSet(double x0, double x1, int n,
                                 const std::vector<std::function<double(double)>>& functions)
    : x0_(x0),
      inv_step_(n > 1 ? (n - 1) / (x1 - x0) : 1.0),
      knots_(static_cast<std::size_t>(std::max(n, 1))),
      columns_(functions.size()) {
  values_.assign(knots_ * columns_, 0.0);
  for (int i = 0; i < n; ++i) {
    // The last knot is x1 exactly (no round-off drift).
    const double x = (i + 1 == n) ? x1 : x0 + (x1 - x0) * i / std::max(n - 1, 1);
    for (std::size_t c = 0; c < columns_; ++c) values_[static_cast<std::size_t>(i) * columns_ + c] = functions[c](x);
  }
}

double UniformTableSet::min_on(std::size_t column, double a, double b) const {
  double m = std::min(eval(a, column), eval(b, column));
  const double last = static_cast<double>(knots_ - 1);
  const double u0 = std::max(0.0, std::ceil((a - x0_) * inv_step_)), u1 = std::min(last, std::floor((b - x0_) * inv_step_));
  for (double u = u0; u <= u1; u += 1.0) m = std::min(m, values_[static_cast<std::size_t>(u) * columns_ + column]);
  return m;
}

}  // namespace skyfarm

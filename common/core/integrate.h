// Deterministic numerical quadrature for smooth 1-D integrands (column
// integrals of density profiles, normalisations).
#pragma once
#include <functional>

namespace skyfarm {

// Adaptive Simpson integration of f over [a, b] to a relative tolerance
// `rel_tol` of the result (absolute floor `abs_tol`), at most `max_depth`
// bisections deep.
double integrate_adaptive_simpson(const std::function<double(double)>& f, double a, double b,
                                  double rel_tol = 1e-10, double abs_tol = 1e-300, int max_depth = 40);

}  // namespace skyfarm

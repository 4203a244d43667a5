// The CIE 1931 2° standard colorimetric observer: colour-matching functions
// x̄(λ), ȳ(λ), z̄(λ) from data/cie1931_2deg_xyz.csv (CIE 018:2004 1-nm table,
// 360–830 nm; provenance in data/README.md), linear between the 1 nm knots and
// zero outside 360–830 nm.
#pragma once

#include "common/core/piecewise_linear.h"
#include "common/spectrum/color.h"

namespace skyfarm {

struct CieObserver {
  PiecewiseLinear xbar, ybar, zbar;  // dimensionless, λ in nm; the same knots (cie1931_cmf relies on it)
  double ybar_integral_nm;           // ∫ ȳ(λ) dλ over 360–830 nm, nm
};

// The observer, parsed from the embedded table once (thread-safe static).
const CieObserver& cie1931_observer();

// (x̄, ȳ, z̄)(λ), returned in an Xyz; 0 outside [360, 830] nm.
Xyz cie1931_cmf(double lambda_nm);
double cie1931_ybar(double lambda_nm);

// ∫ ȳ(λ) dλ over 360–830 nm (exact integral of the linear interpolant, i.e.
// the trapezoid rule on the 1 nm grid) ≈ 106.857 nm; pbrt-v4's CIE_Y_integral
// = 106.856895 is the plain 1 nm sum, which differs by (ȳ(360) + ȳ(830))/2 ≈ 2.5e-6.
double cie1931_ybar_integral_nm();

}  // namespace skyfarm

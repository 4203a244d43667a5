#include "common/spectrum/cie_observer.h"

#include "common/data/csv_table.h"

namespace skyfarm {
namespace {

CieObserver load_observer() {
  const CsvTable t = CsvTable::embedded("cie1931_2deg_xyz.csv");
  const auto& lambda = t.column("wavelength_nm");
  constexpr auto kZero = PiecewiseLinear::Outside::kZero;
  CieObserver o{PiecewiseLinear(lambda, t.column("xbar"), kZero, "cie1931_2deg_xyz.csv xbar"),
                PiecewiseLinear(lambda, t.column("ybar"), kZero, "cie1931_2deg_xyz.csv ybar"),
                PiecewiseLinear(lambda, t.column("zbar"), kZero, "cie1931_2deg_xyz.csv zbar"), 0.0};
  o.ybar_integral_nm = o.ybar.integral(o.ybar.x_min(), o.ybar.x_max());
  return o;
}

}  // namespace

const CieObserver& cie1931_observer() {
  static const CieObserver observer = load_observer();
  return observer;
}

// The three functions share their knots (one wavelength column): one search.
Xyz cie1931_cmf(double lambda_nm) {
  const CieObserver& o = cie1931_observer();
  const PiecewiseLinear::Location at = o.ybar.locate(lambda_nm);
  return {o.xbar.eval_at(at), o.ybar.eval_at(at), o.zbar.eval_at(at)};
}

double cie1931_ybar(double lambda_nm) { return cie1931_observer().ybar(lambda_nm); }

double cie1931_ybar_integral_nm() { return cie1931_observer().ybar_integral_nm; }

}  // namespace skyfarm

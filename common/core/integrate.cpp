#include "common/core/integrate.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace skyfarm {
namespace {

struct Panel {
  double a, b, fa, fm, fb, whole;
};

double simpson(double a, double b, double fa, double fm, double fb) { return (b - a) / 6.0 * (fa + 4.0 * fm + fb); }

// Recursive step of adaptive Simpson (Lyness 1969): accept a panel when its
// two halves agree with it to 15 tol (Richardson correction added).
double refine(const std::function<double(double)>& f, const Panel& p, double tol, int depth) {
  const double m = 0.5 * (p.a + p.b);
  const double lm = 0.5 * (p.a + m), rm = 0.5 * (m + p.b);
  const double flm = f(lm), frm = f(rm);
  const double left = simpson(p.a, m, p.fa, flm, p.fm);
  const double right = simpson(m, p.b, p.fm, frm, p.fb);
  const double delta = left + right - p.whole;
  if (depth <= 0 || std::abs(delta) <= 15.0 * tol) return left + right + delta / 15.0;
  return refine(f, {p.a, m, p.fa, flm, p.fm, left}, 0.5 * tol, depth - 1) +
         refine(f, {m, p.b, p.fm, frm, p.fb, right}, 0.5 * tol, depth - 1);
}

}  // namespace

double integrate_adaptive_simpson(const std::function<double(double)>& f, double a, double b, double rel_tol,
                                  double abs_tol, int max_depth) {
  if (a == b) return 0.0;
  // Start from 16 panels so narrow features are not missed by the first estimate.
  constexpr int kPanels = 16;
  double coarse = 0.0;
  std::vector<Panel> panels;
  for (int i = 0; i < kPanels; ++i) {
    const double pa = a + (b - a) * i / kPanels, pb = a + (b - a) * (i + 1) / kPanels;
    const double fa = f(pa), fm = f(0.5 * (pa + pb)), fb = f(pb);
    panels.push_back({pa, pb, fa, fm, fb, simpson(pa, pb, fa, fm, fb)});
    coarse += panels.back().whole;
  }
  const double tol = std::max(abs_tol, rel_tol * std::abs(coarse)) / kPanels;
  double sum = 0.0;
  for (const auto& p : panels) sum += refine(f, p, tol, max_depth);
  return sum;
}

}  // namespace skyfarm

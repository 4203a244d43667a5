// Bilinear interpolation of per-bin rows stored on a 2-D grid of nodes, the
// look-up of every LUT: four rows of per-bin doubles, at (i, j), (i, j + 1),
// (i + 1, j), (i + 1, j + 1), combined with the weights of the fractional
// positions f_i, f_j in [0, 1].  Convex weights, so non-negative tables give
// non-negative results.
#pragma once
#include <cstddef>

namespace skyfarm::lut {

struct Bilinear {
  const double *v00, *v01, *v10, *v11;
  double w00, w01, w10, w11;

  // base: row (i, j); next_i, next_j: doubles from (i, j) to (i + 1, j) and to (i, j + 1).
  Bilinear(const double* base, std::size_t next_i, std::size_t next_j, double f_i, double f_j)
      : v00(base),
        v01(base + next_j),
        v10(base + next_i),
        v11(base + next_i + next_j),
        w00((1.0 - f_i) * (1.0 - f_j)),
        w01((1.0 - f_i) * f_j),
        w10(f_i * (1.0 - f_j)),
        w11(f_i * f_j) {}

  double at(int b) const { return w00 * v00[b] + w01 * v01[b] + w10 * v10[b] + w11 * v11[b]; }
  // (The loops copy the members first: out may alias nothing of *this, but
  // the compiler cannot know, and would reload them per bin, unvectorised.)
  void eval(int bins, double* out) const {
    const double *a = v00, *b = v01, *c = v10, *d = v11;
    const double wa = w00, wb = w01, wc = w10, wd = w11;
    for (int k = 0; k < bins; ++k) out[k] = wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k];
  }
  // acc[b] += weight[b] * value[b]
  void weighted_add(int bins, const double* weight, double* acc) const {
    const double *a = v00, *b = v01, *c = v10, *d = v11;
    const double wa = w00, wb = w01, wc = w10, wd = w11;
    for (int k = 0; k < bins; ++k) acc[k] += weight[k] * (wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k]);
  }
};

}  // namespace skyfarm::lut

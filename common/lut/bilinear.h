// Bilinear interpolation of per-bin rows stored on a 2-D grid of nodes, the
// look-up of every LUT: four rows of per-bin values, at (i, j), (i, j + 1),
// (i + 1, j), (i + 1, j + 1), combined with the weights of the fractional
// positions f_i, f_j in [0, 1].  Convex weights, so non-negative tables give
// non-negative results.  V is the tables' element type: double for the
// sky-view table, float for the transmittance and multiple-scattering
// tables that the marches read (half the bytes per look-up, twice the values
// per vector instruction; their own accuracy is 1e-3 at best).
#pragma once
#include <cstddef>

namespace skyfarm::lut {

template <class V>
struct BilinearOf {
  const V *v00, *v01, *v10, *v11;
  double w00, w01, w10, w11;

  // base: row (i, j); next_i, next_j: values from (i, j) to (i + 1, j) and to (i, j + 1).
  BilinearOf(const V* base, std::size_t next_i, std::size_t next_j, double f_i, double f_j)
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
    const V *a = v00, *b = v01, *c = v10, *d = v11;
    const double wa = w00, wb = w01, wc = w10, wd = w11;
    for (int k = 0; k < bins; ++k) out[k] = wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k];
  }
  // acc[b] += weight[b] * value[b]
  void weighted_add(int bins, const double* weight, double* acc) const {
    const V *a = v00, *b = v01, *c = v10, *d = v11;
    const double wa = w00, wb = w01, wc = w10, wd = w11;
    for (int k = 0; k < bins; ++k) acc[k] += weight[k] * (wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k]);
  }
  // The same in single precision throughout (the marches' sums over steps).
  void weighted_add(int bins, const float* weight, float* __restrict acc) const {
    const V *a = v00, *b = v01, *c = v10, *d = v11;
    const float wa = static_cast<float>(w00), wb = static_cast<float>(w01), wc = static_cast<float>(w10),
                wd = static_cast<float>(w11);
    for (int k = 0; k < bins; ++k) acc[k] += weight[k] * (wa * a[k] + wb * b[k] + wc * c[k] + wd * d[k]);
  }
};

using Bilinear = BilinearOf<double>;
using BilinearF = BilinearOf<float>;

}  // namespace skyfarm::lut

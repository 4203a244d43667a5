// Transmittance to the top of the atmosphere, T(r, mu) per spectral bin, for
// every ray that does not meet the ground (Hillaire 2020 §4, Bruneton 2017
// "Transmittance"): the sun's visibility from any point of the atmosphere.
//
// Parameters
//   mu_samples      nodes along x_mu (default 256)
//   r_samples       nodes along x_r (default 128; Hillaire uses 64, which
//                   misses the 0.5 % accuracy target near the horizon seen
//                   from 5-30 km by up to 1.5x)
//   steps           quadrature intervals per monotone part of a ray (even,
//                   default 64; a ray that first descends has two parts)
//
// Parameterisation (Bruneton 2017, GetTransmittanceTextureUvFromRMu, with
// H = sqrt(R_top^2 - R^2) the distance to the top along the horizon ray from
// the ground and rho = sqrt(r^2 - R^2) the same from radius r):
//   x_r  = rho / H
//   x_mu = (d - d_min) / (d_max - d_min),  d = distance to the top along mu,
//          d_min = R_top - r (straight up), d_max = rho + H (the horizon),
// so that rays near the horizon, whose transmittance changes fastest, get
// most of the nodes.  Near the horizon x_mu is about linear in the altitude
// of the ray's lowest point, which a low aerosol layer (scale height 1.2 km)
// makes the steepest variable: the mu nodes are therefore equally spaced in
// v = 1 - (1 - x_mu)^(1/4), i.e. they crowd towards the horizon as the 4th
// power (measured on the Earth preset, 256 x 128 nodes, worst error relative
// to the test's tolerance max(0.5 % T, 1e-4): 0.50 with this warp, 0.56 with
// a cube root, 1.2 with a square root, 25 without).  Values are stored at the nodes
// (v = k / (n - 1), x_r = j / (n - 1)), in single precision (bilinear.h), and
// interpolated bilinearly.  Rays below the horizon get T = 0 (the planet
// hides the sun; a hard shadow: the disk's penumbra is not modelled).
//
// Quadrature: along the ray's line, s is the distance past the closest
// approach to the centre (radius l = r sqrt(1 - mu^2)), r(s) = sqrt(l^2 + s^2);
// each monotone part [s_a, s_b] (s_a >= 0) is mapped by s = s_a + (s_b -
// s_a) u^2, so that the samples crowd where the air is densest, and the
// optical depth int sigma_t ds is summed by Simpson's rule in u, for each of
// the medium's extinction terms (medium_table.h: 7 profiles for the Earth,
// whatever the number of bins), then expanded to the bins once per node.
// A ray that first descends has two parts, and its second (from the closest
// approach to the top) is the horizontal ray from there: it comes from a
// table of those rays' terms at the medium's altitude nodes (quadrature on
// 2 x steps intervals), interpolated linearly (transmittance_lut.cpp,
// tangent_table: half the samples of a build, and a smaller error).  Rows
// whose horizontal ray is thin (optical depth below 1 in every bin: above
// ~30 km on the Earth) climb from r on 8-32 intervals, a descending ray
// there as 2 tau_h(l) minus its mirror image's climb (climb_rule).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "common/core/huge_page_allocator.h"
#include "common/lut/bilinear.h"
#include "common/lut/medium_table.h"
#include "common/lut/vector_math.h"

namespace skyfarm {

class TransmittanceLut {
 public:
  static TransmittanceLut build(const MediumTable& medium, int mu_samples = 256, int r_samples = 128, int steps = 64);

  // Where (r, mu) falls in the table, in two parts: the radius part
  // (locate_r, reused for every mu at that radius) and the fractional node
  // position u in [0, mu_samples - 1] along mu (mu_position), -1 for a ray
  // that meets the ground (T = 0).  mu_position is inline and has a single
  // select so that the loops over many mu (a table row's views, every sun
  // of the multiple-scattering table) vectorise: the ground test is d >
  // d_max, i.e. x_mu > 1 before clamping (the distance to the top grows as
  // mu falls, and the horizon ray has d_max), which is lut::ray_hits_ground
  // up to rounding (the 1e-12 margin keeps the horizontal ray from the
  // ground, mu = 0, unblocked).
  struct RadiusCoord {
    double r, r2, top_c, ground_c;  // r, r^2, R_top^2 - r^2, r^2 - R^2 (as (a - b)(a + b))
    double d_min, inv_range;        // R_top - r, 1 / (d_max - d_min)
    std::size_t row;                // offset of node (j, 0), in values
    double fj;                      // weight of row j + 1
  };
  RadiusCoord locate_r(double r) const;
  double mu_position(const RadiusCoord& rc, double mu) const {
    const double d = -rc.r * mu + std::sqrt(rc.r2 * mu * mu + rc.top_c);  // distance to the top
    const double x = (d - rc.d_min) * rc.inv_range;
    const double x_mu = std::min(1.0, std::max(0.0, x));
    const double u = (1.0 - std::sqrt(std::sqrt(1.0 - x_mu))) * (n_mu_ - 1);  // the warp v(x_mu)
    return x > 1.0 + 1e-12 ? -1.0 : u;
  }
  // The four nodes and weights around (rc, u >= 0), for fused loops.
  lut::BilinearF bilinear(const RadiusCoord& rc, double u) const {
    const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_mu_ - 2));
    const std::size_t B = static_cast<std::size_t>(bins_);
    return lut::BilinearF(values_.data() + rc.row + i * B, static_cast<std::size_t>(n_mu_) * B, B, rc.fj,
                          u - static_cast<double>(i));
  }
  // The radius half of that interpolation for the mu nodes [first, first +
  // count): out[m * bins + b] = T at rc's radius and node first + m.  A
  // march step whose many views fall on few nodes builds these once and
  // interpolates along mu only (node_of(u), then linear).
  void radius_rows(const RadiusCoord& rc, std::size_t first, std::size_t count, float* __restrict out) const {
    const std::size_t B = static_cast<std::size_t>(bins_), n = count * B;
    const float* __restrict a = values_.data() + rc.row + first * B;
    const float* __restrict b = a + static_cast<std::size_t>(n_mu_) * B;
    const float f = static_cast<float>(rc.fj), g = 1.0f - f;
    for (std::size_t k = 0; k < n; ++k) out[k] = g * a[k] + f * b[k];
  }
  // For loops that build their own bilinear weights: the values at rc's
  // row and mu node i, and the distance (in values) to the next row.
  const float* node_values(const RadiusCoord& rc, std::size_t i) const {
    return values_.data() + rc.row + i * static_cast<std::size_t>(bins_);
  }
  std::size_t radius_stride() const { return static_cast<std::size_t>(n_mu_) * static_cast<std::size_t>(bins_); }
  // The node i (u in [i, i + 1]) that bilinear() interpolates from, u >= 0.
  std::size_t node_of(double u) const {
    return std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_mu_ - 2));
  }
  // T per bin (bilinear; 0 when u < 0).
  void lookup(const RadiusCoord& rc, double u, double* out) const;
  // acc[b] += weight[b] * T[b] (the marches' inner loop, without a temporary).
  void lookup_weighted_add(const RadiusCoord& rc, double u, const double* weight, double* acc) const;
  // T per bin from radius r along cosine mu to the top.
  void to_top(double r, double mu, double* out) const {
    const RadiusCoord rc = locate_r(r);
    lookup(rc, mu_position(rc, mu), out);
  }

  // The parameterisation and its inverse.
  void unit_from_r_mu(double r, double mu, double* x_r, double* x_mu) const;
  void r_mu_from_unit(double x_r, double x_mu, double* r, double* mu) const;

  // Optical depth per bin from (r, mu) to the top by the quadrature above,
  // every part on `steps` intervals (the table stores exp(-tau) of the same,
  // with a descending ray's second part from the tangent table); rays into
  // the ground are integrated as if the planet were absent.
  static void optical_depth_to_top(const MediumTable& medium, double r, double mu, int steps, double* tau);

  int mu_samples() const { return n_mu_; }
  int r_samples() const { return n_r_; }
  std::size_t memory_bytes() const { return table_memory_bytes(values_); }

 private:
  int bins_ = 0, n_mu_ = 0, n_r_ = 0, steps_ = 0;
  double R_ = 0.0, R_top_ = 0.0, H_ = 0.0;
  TableVector<float> values_;  // [x_r node][x_mu node][bin], single precision (bilinear.h)
};

}  // namespace skyfarm

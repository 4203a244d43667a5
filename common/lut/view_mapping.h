// How the sky-view and aerial-perspective tables lay out the directions seen
// from an observer at radius r inside the atmosphere (Hillaire 2020 §5.3,
// RenderSkyCommon.hlsl UvToSkyViewLutParams, non-linear variant).
//
// Azimuth: only the azimuth phi relative to the sun's matters (the sky is
// mirror-symmetric about the sun's vertical plane), phi in [0, pi]; columns
// u = k / (n - 1) with u = sin(phi / 2), i.e. cos(phi) = 1 - 2 u^2: denser
// towards the sun.
//
// Zenith: the geometric horizon is at the zenith angle zha = pi - beta,
// cos(beta) = sqrt(r^2 - R^2) / r.  Unlike Hillaire's single texture, the
// rows are split at the horizon into two halves that are never interpolated
// into each other (the radiance jumps from sky to ground there):
//   sky rows     v = i / (n_sky - 1):    theta = zha (1 - (1 - v)^2)   (zenith .. horizon)
//   ground rows  v = i / (n_ground - 1): theta = zha + beta v^2        (horizon .. nadir)
// both quadratic, so the rows crowd at the horizon.  The last sky row is the
// ray that grazes the planet (taken as missing it), the first ground row the
// ray that touches it (taken as hitting it).  Whether a direction is sky or
// ground is decided by the exact ray test (lut::ray_hits_ground).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "common/core/constants.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm::lut {

struct ViewMapping {
  double r = 0.0, R = 0.0, zha = 0.5 * kPi, beta = 0.5 * kPi;
  int n_sky = 2, n_ground = 2, n_azimuth = 2;

  ViewMapping() = default;
  ViewMapping(double r_observer, double R_planet, int rows, int azimuth_columns)
      : r(std::max(r_observer, R_planet)),
        R(R_planet),
        n_sky(std::max(2, rows / 2)),
        n_ground(std::max(2, rows - rows / 2)),
        n_azimuth(std::max(2, azimuth_columns)) {
    beta = std::acos(std::clamp(std::sqrt((r - R) * (r + R)) / r, 0.0, 1.0));
    zha = kPi - beta;
  }
  int rows() const { return n_sky + n_ground; }

  // Row index (sky rows first) -> zenith angle, and whether it is a ground row.
  double zenith_of_row(int row, bool* ground) const {
    *ground = row >= n_sky;
    if (!*ground) {
      const double v = static_cast<double>(row) / (n_sky - 1);
      return zha * (1.0 - (1.0 - v) * (1.0 - v));
    }
    const double v = static_cast<double>(row - n_sky) / (n_ground - 1);
    return zha + beta * v * v;
  }
  // cos(phi) of a column.
  double cos_phi_of_column(int column) const {
    const double u = static_cast<double>(column) / (n_azimuth - 1);
    return 1.0 - 2.0 * u * u;
  }

  // Fractional position of a direction: row i0 and weight f_row (interpolate
  // rows i0, i0 + 1, both in the same half), column j0 and weight f_col.
  struct Position {
    std::size_t row, column;
    double f_row, f_column;
    bool ground;
  };
  // mu: cos of the view zenith angle; cos_phi: cos of the azimuth relative to the sun.
  Position locate(double mu, double cos_phi) const {
    Position p;
    p.ground = ray_hits_ground(r, mu, R);
    const double theta = std::acos(std::clamp(mu, -1.0, 1.0));
    double v;
    int n;
    if (!p.ground) {
      v = 1.0 - std::sqrt(std::clamp(1.0 - theta / zha, 0.0, 1.0));
      n = n_sky;
    } else {
      v = std::sqrt(std::clamp((theta - zha) / beta, 0.0, 1.0));
      n = n_ground;
    }
    const double x = v * (n - 1);
    const int i = std::min(static_cast<int>(x), n - 2);
    p.row = static_cast<std::size_t>(i + (p.ground ? n_sky : 0));
    p.f_row = x - i;
    const double u = std::sqrt(std::clamp(0.5 * (1.0 - cos_phi), 0.0, 1.0)) * (n_azimuth - 1);
    const int j = std::min(static_cast<int>(u), n_azimuth - 2);
    p.column = static_cast<std::size_t>(j);
    p.f_column = u - j;
    return p;
  }
};

}  // namespace skyfarm::lut

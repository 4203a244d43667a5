// A test-only, explicit microsurface: a periodic Gaussian random heightfield
// whose slopes follow the Beckmann distribution, triangulated, with an exact
// ray intersection.  It is the "simulated" reference of the multiple-bounce
// models: no Smith assumption, no height distribution, only geometry.
//
// Generation (spectral synthesis): heights on an n x n periodic grid are a
// sum of plane waves on the grid's Fourier lattice, each with a complex
// Gaussian coefficient of variance S(k) = exp(-k^2 l^2 / 4), the spectrum of
// the Gaussian autocorrelation exp(-r^2 / l^2); a sum of Gaussians is
// Gaussian, so heights and slopes are jointly Gaussian and stationary.  Each
// cell is split into two triangles along its (1,0)-(0,1) diagonal: a
// triangle's slopes are differences of neighbouring heights, so they are
// Gaussian too.  The cell sizes dx, dy are then set so that the mean square
// slope of the triangles is exactly alpha_x^2 / 2 along x and alpha_y^2 / 2
// along y, the Beckmann slope distribution's; stretching x and y differently
// is what makes the surface anisotropic.  Every triangle has the same
// projected area, so the distribution of triangle slopes is the slope
// distribution per unit macro area (P22 of the microfacet literature).
//
// Parameters
//   alpha_x, alpha_y  Beckmann roughness along x and y.
//   size              grid samples per side (n); the surface repeats with
//                     period n dx along x and n dy along y.
//   correlation       the correlation length l, in grid cells: large enough
//                     that the triangulated surface is smooth at the scale of
//                     its bumps, small enough that the period holds many
//                     bumps ((size / correlation)^2 independent patches).
//   seed              the coefficients' random stream.
//
// intersect(origin, d): the first point where the ray origin + t d (t > 0)
// crosses the surface from above, found by walking the grid cells the ray
// projects onto (Amanatides and Woo 1987) and, within a cell, the one or two
// triangles it passes over: on a triangle of slopes (p, q) the height of the
// ray above the surface changes at the rate d.z - p d.x - q d.y, so it is hit
// where that linear function turns negative.  The surface is continuous, so a
// ray cannot slip between triangles; a ray leaving a triangle on its front
// side moves up relative to it and is not hit again by it.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "common/material/random_sequence.h"

namespace skyfarm::material::test {

class MicrosurfaceHeightfield {
 public:
  MicrosurfaceHeightfield(double alpha_x, double alpha_y, int size, double correlation, std::uint64_t seed)
      : n_(size), heights_(static_cast<std::size_t>(size) * size, 0.0) {
    synthesize(correlation, seed);
    // Mean square differences along x and y over the whole periodic grid:
    // the two triangles of every cell together use each difference once.
    double sxx = 0.0;
    double syy = 0.0;
    for (int j = 0; j < n_; ++j) {
      for (int i = 0; i < n_; ++i) {
        const double ex = height(i + 1, j) - height(i, j);
        const double ey = height(i, j + 1) - height(i, j);
        sxx += ex * ex;
        syy += ey * ey;
      }
    }
    sxx /= static_cast<double>(n_) * n_;
    syy /= static_cast<double>(n_) * n_;
    dx_ = std::sqrt(sxx) / (alpha_x / std::sqrt(2.0));
    dy_ = std::sqrt(syy) / (alpha_y / std::sqrt(2.0));
    max_height_ = *std::max_element(heights_.begin(), heights_.end());
  }

  int size() const { return n_; }
  double period_x() const { return n_ * dx_; }
  double period_y() const { return n_ * dy_; }
  double max_height() const { return max_height_; }

  // The heights at grid point (i, j), periodic in both indices.
  double height(int i, int j) const {
    return heights_[static_cast<std::size_t>(wrap(j)) * n_ + static_cast<std::size_t>(wrap(i))];
  }

  // The slopes (dz/dx, dz/dy) of the lower (a + b <= 1 in cell coordinates)
  // or upper triangle of cell (i, j).
  glm::dvec2 slopes(int i, int j, bool upper) const {
    if (!upper) return {(height(i + 1, j) - height(i, j)) / dx_, (height(i, j + 1) - height(i, j)) / dy_};
    return {(height(i + 1, j + 1) - height(i, j + 1)) / dx_, (height(i + 1, j + 1) - height(i + 1, j)) / dy_};
  }

  struct Hit {
    glm::dvec3 point;
    glm::dvec3 normal;  // the triangle's, facing up (normal.z > 0)
  };
  enum class Outcome { hit, escaped, lost };
  struct Result {
    Outcome outcome = Outcome::lost;
    Hit hit;
  };

  // The first crossing of the ray into the surface, or escaped (the ray
  // rises above the highest point), or lost (more than max_cells cells
  // without either: a ray rising at a tiny angle).  below_count is
  // incremented when the ray is found more than a rounding error below the
  // surface, which a correct tracer never does.
  Result intersect(const glm::dvec3& origin, const glm::dvec3& d, int* below_count = nullptr,
                   int max_cells = 1 << 20) const {
    // Grid units: u = x / dx, v = y / dy; t is the ray's own parameter.
    const double u0 = origin.x / dx_;
    const double v0 = origin.y / dy_;
    const double du = d.x / dx_;
    const double dv = d.y / dy_;
    long i = static_cast<long>(std::floor(u0));
    long j = static_cast<long>(std::floor(v0));
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const long step_i = du > 0.0 ? 1 : -1;
    const long step_j = dv > 0.0 ? 1 : -1;
    const double delta_u = du != 0.0 ? std::abs(1.0 / du) : kInf;
    const double delta_v = dv != 0.0 ? std::abs(1.0 / dv) : kInf;
    double next_u = du > 0.0 ? (static_cast<double>(i + 1) - u0) / du
                    : du < 0.0 ? (static_cast<double>(i) - u0) / du
                               : kInf;
    double next_v = dv > 0.0 ? (static_cast<double>(j + 1) - v0) / dv
                    : dv < 0.0 ? (static_cast<double>(j) - v0) / dv
                               : kInf;
    double t = 0.0;
    for (int cells = 0; cells < max_cells; ++cells) {
      if (d.z > 0.0 && origin.z + d.z * t > max_height_) return {Outcome::escaped, {}};
      const double t_end = std::min(next_u, next_v);
      // The diagonal a + b = 1 of this cell, crossed at most once.
      const double c_start = (u0 + du * t - static_cast<double>(i)) + (v0 + dv * t - static_cast<double>(j)) - 1.0;
      const double c_rate = du + dv;
      double t_diag = kInf;
      if (c_rate != 0.0) t_diag = t - c_start / c_rate;
      double piece_start = t;
      for (int piece = 0; piece < 2; ++piece) {
        const bool split = t_diag > piece_start && t_diag < t_end;
        const double piece_end = split ? t_diag : t_end;
        // Which triangle: the side of the diagonal at the piece's middle (a
        // ray parallel to the diagonal, e.g. a vertical one, stays on its side).
        const double t_mid = 0.5 * (piece_start + piece_end);
        const bool upper = (c_rate == 0.0 ? c_start : c_start + c_rate * (t_mid - t)) > 0.0;
        if (const std::optional<Hit> hit =
                cross(origin, d, u0, v0, du, dv, i, j, upper, piece_start, piece_end, below_count)) {
          return {Outcome::hit, *hit};
        }
        if (!split) break;
        piece_start = piece_end;
      }
      t = t_end;
      if (next_u < next_v) {
        i += step_i;
        next_u += delta_u;
      } else {
        j += step_j;
        next_v += delta_v;
      }
    }
    return {Outcome::lost, {}};
  }

 private:
  int wrap(long k) const { return static_cast<int>(((k % n_) + n_) % n_); }

  // The ray over one triangle between t0 and t1: the height above it,
  // f(t) = z(t) - surface(t), is linear; a hit where it turns negative.
  std::optional<Hit> cross(const glm::dvec3& origin, const glm::dvec3& d, double u0, double v0, double du,
                           double dv, long i, long j, bool upper, double t0, double t1, int* below_count) const {
    const glm::dvec2 s = slopes(static_cast<int>(wrap(i)), static_cast<int>(wrap(j)), upper);
    const double rate = d.z - s.x * d.x - s.y * d.y;
    if (rate >= 0.0) return std::nullopt;  // rising relative to the triangle
    const double a = u0 + du * t0 - static_cast<double>(i);
    const double b = v0 + dv * t0 - static_cast<double>(j);
    const int ii = static_cast<int>(wrap(i));
    const int jj = static_cast<int>(wrap(j));
    const double surface = upper ? height(ii + 1, jj + 1) + (height(ii + 1, jj + 1) - height(ii, jj + 1)) * (a - 1.0) +
                                       (height(ii + 1, jj + 1) - height(ii + 1, jj)) * (b - 1.0)
                                 : height(ii, jj) + (height(ii + 1, jj) - height(ii, jj)) * a +
                                       (height(ii, jj + 1) - height(ii, jj)) * b;
    const double f0 = origin.z + d.z * t0 - surface;
    if (f0 < -1e-9 && below_count != nullptr) ++*below_count;
    const double f1 = f0 + rate * (t1 - t0);
    if (f1 >= 0.0) return std::nullopt;
    const double t_hit = std::max(t0, t0 + f0 / -rate);
    return Hit{origin + t_hit * d, glm::normalize(glm::dvec3(-s.x, -s.y, 1.0))};
  }

  void synthesize(double correlation, std::uint64_t seed) {
    constexpr double kPi = 3.14159265358979323846;
    // The spectrum's standard deviation per axis is sqrt(2) / l in radians
    // per cell; keep the lattice points within 4.5 of them (the variance
    // left out is below 1e-4 of the total) and below the Nyquist frequency.
    const double sigma_index = std::sqrt(2.0) / correlation * n_ / (2.0 * kPi);
    const int m = std::min(n_ / 2 - 1, static_cast<int>(std::ceil(4.5 * sigma_index)));
    const int width = 2 * m + 1;
    RandomSequence rng(seed);
    auto gaussian = [&rng]() {
      // Box-Muller; 1 - u keeps the logarithm finite.
      const double r = std::sqrt(-2.0 * std::log(1.0 - rng.next()));
      return r * std::cos(2.0 * kPi * rng.next());
    };
    std::vector<std::complex<double>> coefficient(static_cast<std::size_t>(width) * width);
    for (int a = -m; a <= m; ++a) {
      for (int b = -m; b <= m; ++b) {
        const double kx = 2.0 * kPi * a / n_;
        const double ky = 2.0 * kPi * b / n_;
        const double amplitude =
            (a == 0 && b == 0) ? 0.0 : std::sqrt(std::exp(-(kx * kx + ky * ky) * correlation * correlation / 4.0));
        const double re = gaussian();
        const double im = gaussian();
        coefficient[static_cast<std::size_t>(a + m) * width + (b + m)] = amplitude * std::complex<double>(re, im);
      }
    }
    std::vector<std::complex<double>> twiddle(n_);
    for (int k = 0; k < n_; ++k) twiddle[k] = std::polar(1.0, 2.0 * kPi * k / n_);
    auto phase = [&](long index) { return twiddle[static_cast<std::size_t>(((index % n_) + n_) % n_)]; };
    // Separable sum: first over b for every row y, then over a for every x.
    std::vector<std::complex<double>> wave(static_cast<std::size_t>(width) * n_);  // e^{i k_b y}
    for (int b = -m; b <= m; ++b) {
      for (int y = 0; y < n_; ++y) wave[static_cast<std::size_t>(b + m) * n_ + y] = phase(static_cast<long>(b) * y);
    }
    std::vector<std::complex<double>> row(static_cast<std::size_t>(width) * n_);
    for (int a = 0; a < width; ++a) {
      std::complex<double>* out = &row[static_cast<std::size_t>(a) * n_];
      for (int b = 0; b < width; ++b) {
        const std::complex<double> c = coefficient[static_cast<std::size_t>(a) * width + b];
        const std::complex<double>* w = &wave[static_cast<std::size_t>(b) * n_];
        for (int y = 0; y < n_; ++y) {
          out[y] = {out[y].real() + c.real() * w[y].real() - c.imag() * w[y].imag(),
                    out[y].imag() + c.real() * w[y].imag() + c.imag() * w[y].real()};
        }
      }
    }
    // The x-sum with y innermost (contiguous in `row`), into heights_[x][y]
    // first, then transposed.
    std::vector<double> by_x(heights_.size(), 0.0);
    for (int a = -m; a <= m; ++a) {
      const std::complex<double>* r = &row[static_cast<std::size_t>(a + m) * n_];
      for (int x = 0; x < n_; ++x) {
        const std::complex<double> p = phase(static_cast<long>(a) * x);
        double* out = &by_x[static_cast<std::size_t>(x) * n_];
        for (int y = 0; y < n_; ++y) out[y] += r[y].real() * p.real() - r[y].imag() * p.imag();
      }
    }
    double square = 0.0;
    for (int y = 0; y < n_; ++y) {
      for (int x = 0; x < n_; ++x) {
        const double h = by_x[static_cast<std::size_t>(x) * n_ + y];
        heights_[static_cast<std::size_t>(y) * n_ + x] = h;
        square += h * h;
      }
    }
    // Unit RMS height (a choice of unit: only slopes matter to the light).
    const double rms = std::sqrt(square / (static_cast<double>(n_) * n_));
    for (double& h : heights_) h /= rms;
  }

  int n_;
  std::vector<double> heights_;
  double dx_ = 1.0;
  double dy_ = 1.0;
  double max_height_ = 0.0;
};

}  // namespace skyfarm::material::test

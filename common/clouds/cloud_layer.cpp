#include "common/clouds/cloud_layer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "common/clouds/cloud_optics.h"
#include "common/clouds/cloud_profile.h"
#include "common/clouds/shell_intervals.h"
#include "common/clouds/tiled_worley_noise.h"
#include "common/clouds/value_noise.h"
#include "common/geometry/sphere_intersection.h"
#include "common/sampling/sampler.h"

namespace skyfarm {

namespace {

constexpr int kOctaves = 3;
// fBm weights, gain 1/2, normalised: the fBm is a convex combination of
// values in [0, 1), so it lies in [0, 1).
constexpr std::array<double, kOctaves> kOctaveWeight = {4.0 / 7.0, 2.0 / 7.0, 1.0 / 7.0};
// The majorant grid's cells per scale_m: a power of two >= 2^(kOctaves - 1),
// so that a cell lies inside one lattice cell of every octave.
constexpr int kCellsPerScale = 8;
static_assert((kCellsPerScale & (kCellsPerScale - 1)) == 0 && kCellsPerScale >= (1 << (kOctaves - 1)));
// The width of the coverage remap's ramp in fBm units: a cloud's edge goes
// from nothing to full over this rise of the fBm (its standard deviation is 0.131).
constexpr double kCoverageRamp = 0.1;
// Where the ramp starts for coverage c = 0, 0.05, ..., 1: the fBm's (1 - c)
// quantile, so that the share of the area holding cloud (on the profile's
// plateau, before erosion) is c.  Measured over 2e6 random points, seeds
// 1-16 (docs/experiments/2026-12-07-cloud-layer.md); symmetric about 0.5 as
// the fBm's distribution is.  The ends: 1 (above every fBm: no cloud) and
// -kCoverageRamp (the ramp ends at 0: full everywhere).
constexpr std::array<double, 21> kCoverageThreshold = {
    1.0,    0.7149, 0.6721, 0.6416, 0.6163, 0.5940, 0.5736, 0.5543, 0.5358, 0.5178, 0.5000,
    0.4822, 0.4642, 0.4457, 0.4264, 0.4059, 0.3837, 0.3583, 0.3279, 0.2852, -kCoverageRamp};

double coverage_threshold(double coverage) {
  const double x = coverage * 20.0;
  const auto i = static_cast<std::size_t>(std::min(19.0, std::floor(x)));
  const double f = x - static_cast<double>(i);
  return kCoverageThreshold[i] + f * (kCoverageThreshold[i + 1] - kCoverageThreshold[i]);
}
// The largest erosion amount: (d - a) / (1 - a) stays finite.
constexpr double kMaxErosion = 0.99;
// |grad fbm| per lattice unit is at most sum_o w_o 2^o x 1.875 (the quintic
// fade's steepest slope) x sqrt(3) = 5.57: a point known to err_m metres
// moves the fBm by at most 6 err_m / scale_m.
constexpr double kFbmLipschitz = 6.0;
// Salts that keep the octaves' and the detail's hashes apart.
constexpr std::uint64_t kNoiseSalt = 0x636c6f75644c6179ULL;  // "cloudLay"

void check(bool ok, const char* what, double value) {
  if (!ok) throw std::invalid_argument(std::string("cloud layer: ") + what + ", got " + std::to_string(value));
}

}  // namespace

struct CloudLayer::Impl {
  CloudLayerSpec spec;
  double radius = 0.0, r_bottom = 0.0, r_top = 0.0;
  glm::dvec3 drift{0.0};
  CloudOptics optics;
  double sigma_max = 0.0;
  CloudProfile profile;
  TiledWorleyNoise detail;
  std::array<std::uint64_t, kOctaves> octave_seed{};
  double inv_scale = 0.0;           // 1 / scale_m
  double inv_detail_spacing = 0.0;  // 1 / (one table sample, m)
  double coverage_lo = 0.0;       // the fBm where the remap's ramp starts
  bool empty = false;             // coverage 0 or sigma_max 0: no cloud at all

  Impl(const CloudLayerSpec& s, double planet_radius_m, const glm::dvec3& drift_m)
      : spec(s),
        radius(planet_radius_m),
        drift(drift_m),
        profile(CloudProfile::for_type(s.type)),
        detail(hash_keys(s.seed, kNoiseSalt, kOctaves, 0)) {
    check(planet_radius_m > 0.0 && std::isfinite(planet_radius_m), "the planet radius must be > 0", planet_radius_m);
    check(s.coverage >= 0.0 && s.coverage <= 1.0, "coverage must be in [0, 1]", s.coverage);
    check(s.erosion >= 0.0 && s.erosion <= 1.0, "erosion must be in [0, 1]", s.erosion);
    check(s.base_m >= 0.0 && std::isfinite(s.base_m), "base_m must be >= 0", s.base_m);
    check(s.thickness_m > 0.0 && std::isfinite(s.thickness_m), "thickness_m must be > 0", s.thickness_m);
    check(s.scale_m > 0.0 && std::isfinite(s.scale_m), "scale_m must be > 0", s.scale_m);
    check(s.detail_scale_m > 0.0 && std::isfinite(s.detail_scale_m), "detail_scale_m must be > 0", s.detail_scale_m);
    check(s.water_content_g_m3 >= 0.0 && std::isfinite(s.water_content_g_m3), "water_content_g_m3 must be >= 0",
          s.water_content_g_m3);
    check(s.optical_depth >= 0.0 && std::isfinite(s.optical_depth), "optical_depth must be >= 0", s.optical_depth);
    for (const double c : {drift_m.x, drift_m.y, drift_m.z}) check(std::isfinite(c), "the drift must be finite", c);
    r_bottom = radius + s.base_m;
    r_top = radius + s.base_m + s.thickness_m;
    optics = cloud_optics(s.particle, s.effective_radius_um);
    sigma_max = s.optical_depth > 0.0 ? s.optical_depth / (s.thickness_m * profile.integral())
                                      : s.water_content_g_m3 * optics.extinction_per_g_m3;
    for (int o = 0; o < kOctaves; ++o)
      octave_seed[static_cast<std::size_t>(o)] = hash_keys(s.seed, kNoiseSalt, static_cast<std::uint64_t>(o), 0);
    inv_scale = 1.0 / s.scale_m;
    inv_detail_spacing = TiledWorleyNoise::kSize / (s.detail_scale_m * TiledWorleyNoise::kCells);
    coverage_lo = coverage_threshold(s.coverage);
    empty = s.coverage == 0.0 || !(sigma_max > 0.0);
  }

  // The coverage remap, monotone in the fBm: 0 for fbm <= lo, 1 for
  // fbm >= lo + ramp (division, not a reciprocal, so that coverage 1 gives
  // exactly 1 at fbm = 0: (0 + ramp) / ramp).
  double shape_of(double fbm) const { return std::clamp((fbm - coverage_lo) / kCoverageRamp, 0.0, 1.0); }

  double density(const glm::dvec3& p) const {
    if (empty) return 0.0;
    const double h = glm::length(p) - radius;
    if (!(h >= spec.base_m && h <= spec.base_m + spec.thickness_m)) return 0.0;
    const double prof = profile((h - spec.base_m) / spec.thickness_m);
    if (prof == 0.0) return 0.0;
    const glm::dvec3 q = p - drift;
    const glm::dvec3 x = q * inv_scale;  // within an ulp of q / scale_m: the walk's margin covers it
    // Octave by octave, stopping once even full values of the octaves left
    // could not lift the fBm over the coverage threshold (clear air is the
    // common case at low coverage).
    double fbm = 0.0, frequency = 1.0, rest = 1.0;
    for (int o = 0; o < kOctaves; ++o, frequency *= 2.0) {
      const auto i = static_cast<std::size_t>(o);
      fbm += kOctaveWeight[i] * value_noise(octave_seed[i], x * frequency);
      rest -= kOctaveWeight[i];
      if (fbm + rest <= coverage_lo) return 0.0;
    }
    const double shape = shape_of(fbm);
    if (shape == 0.0) return 0.0;
    double d = shape * prof;
    if (spec.erosion > 0.0) {
      const double a = std::min(kMaxErosion, spec.erosion * detail.lookup(q * inv_detail_spacing));
      d = std::min(d, std::max(0.0, (d - a) / (1.0 - a)));
    }
    return d;
  }

  // The shape's bound over the majorant grid's cell c (kCellsPerScale per
  // scale_m, so inside one lattice cell of every octave): each octave's
  // maximum over the box (its corners, value_noise.h), plus the margin for
  // points placed err_m off; the finer octaves only when the coarser ones
  // leave the cell possibly cloudy.
  double cell_shape_bound(std::int64_t cx, std::int64_t cy, std::int64_t cz, double fbm_margin,
                          std::array<ValueNoiseCell, kOctaves>& cache) const {
    const glm::dvec3 lo = glm::dvec3(static_cast<double>(cx), static_cast<double>(cy), static_cast<double>(cz)) /
                          static_cast<double>(kCellsPerScale);  // exact: a power of two
    const glm::dvec3 hi = lo + 1.0 / kCellsPerScale;
    double known = fbm_margin, rest = 1.0, frequency = 1.0;
    for (int o = 0; o < kOctaves; ++o, frequency *= 2.0) {
      const auto i = static_cast<std::size_t>(o);
      rest -= kOctaveWeight[i];
      known += kOctaveWeight[i] * value_noise_box_max(octave_seed[i], lo * frequency, hi * frequency, cache[i]);
      if (shape_of(known + std::max(0.0, rest)) == 0.0) return 0.0;
    }
    return shape_of(known);
  }
};

CloudLayer::CloudLayer(const CloudLayerSpec& spec, double planet_radius_m, const glm::dvec3& drift_m)
    : impl_(std::make_unique<Impl>(spec, planet_radius_m, drift_m)) {}
CloudLayer::~CloudLayer() = default;

double CloudLayer::density(const glm::dvec3& p) const { return impl_->density(p); }
double CloudLayer::sigma_t(const glm::dvec3& p) const { return impl_->sigma_max * impl_->density(p); }
double CloudLayer::sigma_max() const { return impl_->sigma_max; }
const CloudOptics& CloudLayer::optics() const { return impl_->optics; }
double CloudLayer::bottom_altitude_m() const { return impl_->spec.base_m; }
double CloudLayer::top_altitude_m() const { return impl_->spec.base_m + impl_->spec.thickness_m; }

void CloudLayer::for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const {
  const Impl& m = *impl_;
  if (m.empty) return;
  const ShellIntervals shell = shell_intervals(ray, m.r_bottom, m.r_top, t_begin, t_end);
  if (shell.count == 0) return;
  const double t_last = shell.t1[static_cast<std::size_t>(shell.count - 1)];
  const double cell_m = m.spec.scale_m / kCellsPerScale, base = m.spec.base_m, thickness = m.spec.thickness_m;

  // How far a point's coordinates may be off between this traversal and
  // sigma_t (o + t d - drift vs (o - drift) + t d, |p| vs the radial form):
  // a few ulps of the largest magnitude involved, and 1 mm for the altitude.
  const double err_m = 16.0 * std::numeric_limits<double>::epsilon() *
                       (glm::length(m.drift) + glm::length(ray.o) + std::abs(t_last) + m.r_top);
  const double fbm_margin = 1e-12 + kFbmLipschitz * err_m / m.spec.scale_m;
  const double altitude_margin = 1e-3 + err_m;

  // The altitude bins' boundaries along the ray, sorted: r(t)^2 = l^2 + (t + b)^2.
  const RadialRay radial = radial_ray(ray);
  std::array<double, 2 * (kAltitudeBins - 1)> breaks{};
  int n_breaks = 0;
  for (int k = 1; k < kAltitudeBins; ++k) {
    const SphereHit hit = intersect_sphere(radial, m.r_bottom + thickness * k / kAltitudeBins);
    if (!hit.hit) continue;
    for (const double t : {hit.t_near, hit.t_far})
      if (t > t_begin && t < t_last) breaks[static_cast<std::size_t>(n_breaks++)] = t;
  }
  std::sort(breaks.begin(), breaks.begin() + n_breaks);
  int next_break = 0;

  // Pieces go out through a one-piece buffer that merges equal neighbours.
  bool stopped = false, pending = false;
  double p0 = 0.0, p1 = 0.0, p_sigma = 0.0;
  const auto flush = [&] {
    if (pending && !stopped) stopped = !visit(p0, p1, p_sigma);
    pending = false;
  };
  const auto emit = [&](double t0, double t1, double sigma) {
    if (!(sigma > 0.0) || !(t1 > t0)) return;
    if (pending && p1 == t0 && p_sigma == sigma) {
      p1 = t1;
      return;
    }
    flush();
    pending = true;
    p0 = t0, p1 = t1, p_sigma = sigma;
  };
  // The profile's bound over the ray's altitudes on [t0, t1]: r(t) is
  // convex, largest at an end, smallest at the closest approach (clamped).
  const auto profile_bound = [&](double t0, double t1) {
    const auto r_at = [&](double t) { return std::sqrt(radial.l * radial.l + (t + radial.b) * (t + radial.b)); };
    const double r_min = r_at(std::clamp(-radial.b, t0, t1)), r_max = std::max(r_at(t0), r_at(t1));
    const double x0 = (r_min - m.radius - base - altitude_margin) / thickness;
    const double x1 = (r_max - m.radius - base + altitude_margin) / thickness;
    return m.profile.max_over(x0, x1);
  };
  // One cell's piece [t0, t1], split at the altitude bins' boundaries.
  const auto cell_piece = [&](double t0, double t1, double shape_bound) {
    while (next_break < n_breaks && breaks[static_cast<std::size_t>(next_break)] <= t0) ++next_break;
    int b = next_break;
    double t = t0;
    while (!stopped) {
      const double t_split = b < n_breaks ? std::min(breaks[static_cast<std::size_t>(b)], t1) : t1;
      emit(t, t_split, m.sigma_max * (shape_bound * profile_bound(t, t_split)));
      if (t_split >= t1) break;
      t = t_split;
      ++b;
    }
  };

  std::array<ValueNoiseCell, kOctaves> lattice_cache;  // neighbouring cells share lattice values
  const glm::dvec3 o = ray.o - m.drift;  // the ray in the noise's frame
  const glm::dvec3& d = ray.d;
  for (int s = 0; s < shell.count && !stopped; ++s) {
    const double a = shell.t0[static_cast<std::size_t>(s)], b = shell.t1[static_cast<std::size_t>(s)];
    // 3-D DDA through the majorant grid (Amanatides & Woo 1987), each
    // boundary's t computed from its integer index (no accumulated error).
    const glm::dvec3 start = (o + a * d) / cell_m;
    std::array<std::int64_t, 3> cell{static_cast<std::int64_t>(std::floor(start.x)),
                                     static_cast<std::int64_t>(std::floor(start.y)),
                                     static_cast<std::int64_t>(std::floor(start.z))};
    std::array<double, 3> t_next{};
    std::array<int, 3> step{};
    const auto boundary_t = [&](int axis) {
      const auto i = static_cast<std::size_t>(axis);
      if (step[i] == 0) return std::numeric_limits<double>::infinity();
      const std::int64_t face = step[i] > 0 ? cell[i] + 1 : cell[i];
      return (static_cast<double>(face) * cell_m - o[axis]) / d[axis];
    };
    for (int axis = 0; axis < 3; ++axis) {
      step[static_cast<std::size_t>(axis)] = d[axis] > 0.0 ? 1 : d[axis] < 0.0 ? -1 : 0;
      t_next[static_cast<std::size_t>(axis)] = boundary_t(axis);
    }
    double t = a;
    while (t < b && !stopped) {
      const int axis = t_next[0] <= t_next[1] ? (t_next[0] <= t_next[2] ? 0 : 2) : (t_next[1] <= t_next[2] ? 1 : 2);
      const auto i = static_cast<std::size_t>(axis);
      const double t_exit = std::min(t_next[i], b);
      if (t_exit > t) {
        const double shape_bound = m.cell_shape_bound(cell[0], cell[1], cell[2], fbm_margin, lattice_cache);
        if (shape_bound > 0.0) cell_piece(t, t_exit, shape_bound);
        t = t_exit;
      }
      cell[i] += step[i];
      t_next[i] = boundary_t(axis);
    }
  }
  flush();
}

}  // namespace skyfarm

#include "common/lut/lut_sky.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"
#include "common/lut/aerial_perspective_lut.h"
#include "common/lut/ground_irradiance_lut.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/medium_table.h"
#include "common/lut/multiple_scattering_bands.h"
#include "common/lut/multiple_scattering_lut.h"
#include "common/lut/scattering_march.h"
#include "common/lut/shell_geometry.h"
#include "common/lut/sky_view_lut.h"
#include "common/lut/transmittance_lut.h"

namespace skyfarm {

// Look-ups keep their per-bin temporaries on the stack.
inline constexpr int kMaxBins = 512;

struct LutSky::Tables {
  SpectralGrid grid;
  MediumTable medium;
  TransmittanceLut transmittance;
  MultipleScatteringLut multiple_scattering;
  GroundIrradianceLut ground_irradiance;
  MultipleScatteringBands bands;
};

LutSky LutSky::build(const Atmosphere& atmosphere, const Sun& sun, double observer_altitude_m, double lambda_min_nm,
                     double lambda_max_nm, const LutResolution& res) {
  if (res.spectral_bins > kMaxBins)
    throw lut::invalid_argument("LUT sky: at most ", kMaxBins, " spectral bins, got ", res.spectral_bins);
  auto tables = std::make_shared<Tables>();
  tables->grid = SpectralGrid(lambda_min_nm, lambda_max_nm, res.spectral_bins);
  tables->medium = MediumTable::build(atmosphere, tables->grid, res.medium_altitude_samples, res.phase_samples);
  tables->transmittance =
      TransmittanceLut::build(tables->medium, res.transmittance_mu, res.transmittance_r, res.transmittance_steps);
  tables->multiple_scattering = MultipleScatteringLut::build(
      tables->medium, tables->transmittance, res.multiple_scattering_mu_s, res.multiple_scattering_altitude,
      res.multiple_scattering_directions, res.multiple_scattering_steps);
  tables->ground_irradiance = GroundIrradianceLut::build(tables->medium, tables->transmittance,
                                                         tables->multiple_scattering, res.ground_irradiance_mu_s,
                                                         res.ground_irradiance_directions, res.ground_irradiance_steps);
  tables->bands = MultipleScatteringBands::build(tables->medium, tables->transmittance, tables->ground_irradiance,
                                                 res.bands, res.bands_mu_s, res.bands_altitude, res.bands_rings,
                                                 res.bands_azimuths, res.bands_steps);
  LutSky sky;
  sky.tables_ = std::move(tables);
  sky.resolution_ = res;
  return sky.with_sun(sun, observer_altitude_m);
}

LutSky LutSky::with_sun(const Sun& sun, double observer_altitude_m) const {
  const Tables& t = *tables_;
  LutSky sky;
  sky.tables_ = tables_;
  sky.resolution_ = resolution_;
  sky.sanitized_ = std::make_shared<std::atomic<std::uint64_t>>(0);
  sky.sun_ = std::make_shared<const Sun>(sun);
  const int B = t.grid.size();
  sky.sun_E_.resize(static_cast<std::size_t>(B));
  sky.sun_L_.resize(static_cast<std::size_t>(B));
  for (int b = 0; b < B; ++b) {
    sky.sun_E_[static_cast<std::size_t>(b)] = t.grid.bin_mean([&](double l) { return sun.irradiance(l); }, b);
    sky.sun_L_[static_cast<std::size_t>(b)] = t.grid.bin_mean([&](double l) { return sun.radiance(l); }, b);
  }
  sky.observer_altitude_m_ = std::max(0.0, observer_altitude_m);
  sky.observer_r_ = t.medium.planet_radius_m() + sky.observer_altitude_m_;
  sky.above_ = sky.observer_altitude_m_ > t.medium.top_altitude_m();
  if (!sky.above_) {
    const double mu_s = sun.direction().z;
    const LutResolution& r = resolution_;
    sky.sky_view_ = std::make_shared<const SkyViewLut>(
        SkyViewLut::build(t.medium, t.transmittance, t.multiple_scattering, t.ground_irradiance, sky.observer_r_, mu_s,
                          sky.sun_E_, r.sky_view_azimuth, r.sky_view_zenith, r.sky_view_steps, &t.bands,
                          BandViewGrid{r.sky_view_band_row_stride, r.sky_view_band_column_stride,
                                       r.sky_view_band_steps}));
    sky.aerial_ = std::make_shared<const AerialPerspectiveLut>(
        AerialPerspectiveLut::build(t.medium, t.transmittance, t.multiple_scattering, sky.observer_r_, mu_s, sky.sun_E_,
                                    r.aerial_azimuth, r.aerial_zenith, r.aerial_slices, r.aerial_max_distance_m));
  }
  return sky;
}

const SpectralGrid& LutSky::grid() const { return tables_->grid; }

namespace {

// cos of the azimuth between the horizontal projections of v and s; 1 when
// either is vertical (every azimuth is the same there).
double cos_relative_azimuth(const glm::dvec3& v, const glm::dvec3& s) {
  const double hv = std::hypot(v.x, v.y), hs = std::hypot(s.x, s.y);
  if (hv == 0.0 || hs == 0.0) return 1.0;
  return std::clamp((v.x * s.x + v.y * s.y) / (hv * hs), -1.0, 1.0);
}

void check_size(std::span<double> out, int bins, const char* what) {
  if (out.size() < static_cast<std::size_t>(bins))
    throw lut::invalid_argument("LUT sky: ", what, " needs ", bins, " values, got ", out.size());
}

}  // namespace

void LutSky::radiance(const glm::dvec3& view_dir, std::span<double> out, bool include_sun_disk) const {
  const Tables& t = *tables_;
  const int B = t.grid.size();
  check_size(out, B, "radiance");
  const double len = glm::length(view_dir);
  if (!(len > 0.0) || !std::isfinite(len)) {
    std::fill(out.begin(), out.begin() + B, 0.0);
    return;
  }
  const glm::dvec3 v = view_dir / len;
  if (above_) {
    raymarch_radiance({0.0, 0.0, observer_r_}, v, out, include_sun_disk, resolution_.space_view_steps);
    return;
  }
  if (refraction_) {
    refracted_radiance(v, out, include_sun_disk);
    return;
  }
  sky_view_->lookup(v.z, cos_relative_azimuth(v, sun_->direction()), out.data());
  if (include_sun_disk && sun_->contains(v)) {
    std::array<double, kMaxBins> T;
    t.transmittance.to_top(observer_r_, v.z, T.data());  // 0 where the planet hides it
    for (int b = 0; b < B; ++b)
      out[static_cast<std::size_t>(b)] += sun_L_[static_cast<std::size_t>(b)] * T[static_cast<std::size_t>(b)];
  }
  sanitize(out.first(static_cast<std::size_t>(B)));
}

std::optional<RefractedView::Apparent> LutSky::disk_sample_direction(const glm::dvec3& d) const {
  if (!refraction_) return RefractedView::Apparent{d, 1.0};
  return refraction_->apparent_direction(d, 550.0);
}

bool LutSky::sees_sun_disk(const glm::dvec3& v) const {
  if (!refraction_) return sun_->contains(v);
  const auto seen = refraction_->true_direction(v, 550.0);
  return seen && sun_->contains(*seen);
}

LutSky LutSky::refracted() const {
  LutSky sky = *this;
  if (!above_)
    sky.refraction_ = std::make_shared<const RefractedView>(observer_altitude_m_, planet_radius_m(),
                                                            tables_->medium.top_radius_m() - planet_radius_m());
  return sky;
}

// radiance() through refracted_view.h: the sky at its mapped direction, the
// disk bin by bin where the view's true direction at the bin's centre
// wavelength lies in it (only views within a degree of the sun are mapped).
void LutSky::refracted_radiance(const glm::dvec3& v, std::span<double> out, bool include_sun_disk) const {
  const Tables& t = *tables_;
  const int B = t.grid.size();
  const glm::dvec3 sky = refraction_->sky_direction(v);
  sky_view_->lookup(sky.z, cos_relative_azimuth(sky, sun_->direction()), out.data());
  const double near_sun = std::cos(sun_->angular_radius_rad() + 1.0 * kDegToRad);
  if (include_sun_disk && !sun_->is_point() && glm::dot(v, sun_->direction()) > near_sun) {
    std::array<double, kMaxBins> T;
    t.transmittance.to_top(observer_r_, v.z, T.data());  // 0 where the planet hides it
    for (int b = 0; b < B; ++b) {
      const auto seen = refraction_->true_direction(v, t.grid.centre_nm(b));
      if (seen && sun_->contains(*seen))
        out[static_cast<std::size_t>(b)] += sun_L_[static_cast<std::size_t>(b)] * T[static_cast<std::size_t>(b)];
    }
  }
  sanitize(out.first(static_cast<std::size_t>(B)));
}

void LutSky::aerial_perspective(const glm::dvec3& view_dir, double distance_m, std::span<double> L_in,
                                std::span<double> T) const {
  const int B = tables_->grid.size();
  check_size(L_in, B, "aerial perspective");
  check_size(T, B, "aerial perspective");
  const glm::dvec3 v = glm::normalize(view_dir);
  const double d = std::max(0.0, distance_m);
  if (above_ || d > aerial_->max_distance_m()) {
    march({0.0, 0.0, observer_r_}, v, d, resolution_.space_view_steps, false, false, L_in.data(), T.data());
  } else {
    aerial_->lookup(v.z, cos_relative_azimuth(v, sun_->direction()), d, L_in.data(), T.data());
  }
  sanitize(L_in.first(static_cast<std::size_t>(B)));
  sanitize(T.first(static_cast<std::size_t>(B)));
  for (int b = 0; b < B; ++b)
    T[static_cast<std::size_t>(b)] = std::min(1.0, T[static_cast<std::size_t>(b)]);  // rounding of the bilinear weights
}

void LutSky::raymarch_radiance(const glm::dvec3& origin, const glm::dvec3& dir, std::span<double> out,
                               bool include_sun_disk, int steps) const {
  const int B = tables_->grid.size();
  check_size(out, B, "raymarch");
  std::array<double, kMaxBins> T;
  march(origin, glm::normalize(dir), std::numeric_limits<double>::infinity(), steps, true, include_sun_disk, out.data(),
        T.data());
  sanitize(out.first(static_cast<std::size_t>(B)));
}

void LutSky::raymarch_aerial_perspective(const glm::dvec3& origin, const glm::dvec3& dir, double distance_m,
                                         std::span<double> L_in, std::span<double> T, int steps) const {
  const int B = tables_->grid.size();
  check_size(L_in, B, "raymarch");
  check_size(T, B, "raymarch");
  march(origin, glm::normalize(dir), std::max(0.0, distance_m), steps, false, false, L_in.data(), T.data());
  sanitize(L_in.first(static_cast<std::size_t>(B)));
  sanitize(T.first(static_cast<std::size_t>(B)));
}

// One ray: clip to the shell (entering from above if need be), then
// scattering_march.h with the exact phase functions, times E_sun.
void LutSky::march(const glm::dvec3& origin, const glm::dvec3& d, double t_max, int steps, bool ground, bool sun_disk,
                   double* L, double* T) const {
  const Tables& t = *tables_;
  const int B = t.grid.size();
  const double R = t.medium.planet_radius_m(), R_top = t.medium.top_radius_m();
  std::fill(L, L + B, 0.0);
  std::fill(T, T + B, 1.0);
  const bool sees_sun = sun_disk && sun_->contains(d);
  glm::dvec3 o = origin;
  double r0 = glm::length(o);
  if (r0 > R_top) {  // from space: start where the ray enters the atmosphere
    const SphereHit hit = intersect_sphere(Ray{o, d}, R_top);
    if (!hit.hit || hit.t_far <= 0.0) {
      if (sees_sun)
        for (int b = 0; b < B; ++b) L[b] = sun_L_[static_cast<std::size_t>(b)];
      return;
    }
    const double t_entry = std::max(0.0, hit.t_near);
    o += t_entry * d;
    t_max -= t_entry;
    r0 = R_top;
    if (!(t_max > 0.0)) return;
  }
  r0 = std::clamp(r0, R, R_top);
  const glm::dvec3 up = glm::normalize(o);
  const double mu = std::clamp(glm::dot(d, up), -1.0, 1.0);
  const double mu_s0 = glm::dot(sun_->direction(), up), nu = glm::dot(d, sun_->direction());
  const bool hits = lut::ray_hits_ground(r0, mu, R);
  const double t_exit = hits ? lut::distance_to_ground(r0, mu, R) : lut::distance_to_top(r0, mu, R_top);
  const double t_end = std::min(t_exit, t_max);
  ScatteringMarch m(t.medium, t.transmittance, &t.multiple_scattering, &t.ground_irradiance);
  m.prepare(r0, mu, t_end, ground && hits && t_exit <= t_max, std::max(1, steps));
  const std::size_t CB = static_cast<std::size_t>(t.medium.scatterers() * B);
  std::array<double, kMaxBins * 4> phase;  // scatterers x bins
  std::array<float, kMaxBins * 4> phase_f;
  std::vector<double> phase_heap;
  std::vector<float> phase_f_heap;
  double* P = phase.data();
  float* P_f = phase_f.data();
  if (CB > phase.size()) {
    phase_heap.resize(CB);
    phase_f_heap.resize(CB);
    P = phase_heap.data();
    P_f = phase_f_heap.data();
  }
  t.medium.phase_exact(nu, P);
  std::copy(P, P + CB, P_f);  // (to float, as the march uses it)
  m.add_inscattering(P_f, nu, mu_s0, 0, m.steps(), L);
  m.add_ground(nu, mu_s0, L);
  // The bands on sky rays, as the sky-view table has them; the aerial
  // perspective (ground = false) keeps the isotropic term, as its table.
  // (Clamped at 0 like the table's entries: the bands alone can dip below.)
  if (ground) {
    m.add_bands(t.bands, nu, mu_s0, L);
    for (int b = 0; b < B; ++b) L[b] = std::max(0.0, L[b]);
  }
  for (int b = 0; b < B; ++b) {
    L[b] *= sun_E_[static_cast<std::size_t>(b)];
    T[b] = m.T_before(m.steps())[b];
  }
  if (sees_sun && !hits && t_exit <= t_max)
    for (int b = 0; b < B; ++b) L[b] += sun_L_[static_cast<std::size_t>(b)] * T[b];
}

void LutSky::transmittance_to_top(double r, double mu, std::span<double> out) const {
  check_size(out, tables_->grid.size(), "transmittance");
  tables_->transmittance.to_top(r, std::clamp(mu, -1.0, 1.0), out.data());
}

double LutSky::planet_radius_m() const { return tables_->medium.planet_radius_m(); }

void LutSky::sanitize(std::span<double> values) const {
  for (double& x : values)
    if (!(x >= 0.0) || !std::isfinite(x)) {
      x = 0.0;
      sanitized_->fetch_add(1, std::memory_order_relaxed);
    }
}

std::uint64_t LutSky::sanitized_values() const { return sanitized_->load(std::memory_order_relaxed); }

int LutSky::clamped_multiple_scattering_nodes() const { return tables_->multiple_scattering.clamped_nodes(); }

std::size_t LutSky::memory_bytes() const {
  const Tables& t = *tables_;
  std::size_t n = t.medium.memory_bytes() + t.transmittance.memory_bytes() + t.multiple_scattering.memory_bytes() +
                  t.ground_irradiance.memory_bytes() + t.bands.memory_bytes() + (sun_E_.size() + sun_L_.size()) * sizeof(double);
  if (sky_view_) n += sky_view_->memory_bytes();
  if (aerial_) n += aerial_->memory_bytes();
  return n;
}

}  // namespace skyfarm

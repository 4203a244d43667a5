#include "common/render/radiance_control.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/lut/lut_sky.h"
#include "common/lut/spectral_grid.h"
#include "common/render/sun_angle_nodes.h"

namespace skyfarm {

namespace {

// cos of the horizon's zenith angle seen from radius r over a planet of radius R.
double horizon_mu(double r, double R) { return -std::sqrt(std::max(0.0, 1.0 - (R / r) * (R / r))); }

}  // namespace

RadianceControl::RadianceControl(const Scene& scene, const RadianceControlResolution& resolution) : res_(resolution) {
  if (res_.altitudes < 2 || res_.view_rows < 2 || res_.sun_angles < 2 || res_.azimuths < 2 || res_.bins < 1 ||
      res_.steps < 1 || !(res_.sun_window_deg > 0.0))
    throw std::invalid_argument("RadianceControl: every axis needs 2 nodes or more");
  const Atmosphere& atmosphere = scene.atmosphere();
  R_ = atmosphere.planet_radius_m();
  top_ = atmosphere.top_radius_m() - R_;
  sun_ = scene.sun().direction();
  const SunZenithWindow window = vertex_sun_zenith_window(scene, res_.sun_window_deg);
  sun_zenith_lo_ = window.lo;
  sun_zenith_step_ = (window.hi - sun_zenith_lo_) / (res_.sun_angles - 1);
  lambda_min_ = scene.lambda_min_nm();
  const double range_nm = scene.lambda_max_nm() - scene.lambda_min_nm();
  bins_ = std::clamp(static_cast<int>(range_nm / 20.0), 1, res_.bins);
  bin_width_ = range_nm / bins_;

  const LutResolution lut = lut_resolution(bins_);
  const LutSky sky = LutSky::build(atmosphere, scene.sun(), scene.observer_altitude_m(), scene.lambda_min_nm(),
                                   scene.lambda_max_nm(), lut);
  values_.assign(index(res_.altitudes, 0, 0, 0), 0.0f);
  std::vector<double> L(static_cast<std::size_t>(bins_));
  for (int a = 0; a < res_.altitudes; ++a)
    for (int m = 0; m < res_.view_rows; ++m)
      for (int s = 0; s < res_.sun_angles; ++s)
        for (int k = 0; k < res_.azimuths; ++k) {
          glm::dvec3 p, wi;
          node_geometry(a, m, s, k, &p, &wi);
          sky.raymarch_radiance(p, wi, L, false, res_.steps);
          float* out = &values_[index(a, m, s, k)];
          for (int b = 0; b < bins_; ++b) {
            const double v = L[static_cast<std::size_t>(b)];
            out[b] = std::isfinite(v) && v > 0.0 ? static_cast<float>(v) : 0.0f;
          }
        }
}

LutResolution RadianceControl::lut_resolution(int bins) {
  LutResolution r;
  r.spectral_bins = bins;
  r.transmittance_mu = 64;
  r.transmittance_r = 32;
  r.transmittance_steps = 32;
  r.multiple_scattering_mu_s = 16;
  r.multiple_scattering_altitude = 16;
  r.multiple_scattering_directions = 32;
  r.multiple_scattering_steps = 10;
  r.ground_irradiance_mu_s = 16;
  r.ground_irradiance_directions = 32;
  r.ground_irradiance_steps = 10;
  r.sky_view_azimuth = 16;  // the sky-view and aerial tables are not read
  r.sky_view_zenith = 16;
  r.sky_view_steps = 4;
  r.aerial_azimuth = 4;
  r.aerial_zenith = 4;
  r.aerial_slices = 4;
  // Hillaire's isotropic term alone: a control and a guide stay unbiased
  // whatever sky they are given, the bands would cost every path-traced
  // render another table, and without them a path-traced image keeps its
  // bytes.
  r.bands = 0;
  return r;
}

double RadianceControl::altitude_of(int a) const {
  const double u = static_cast<double>(a) / (res_.altitudes - 1);
  return top_ * u * u;
}

// View rows: v = m / (rows - 1); below v = 1/2 the ground side, above it the
// sky side, each quadratic in its distance from the horizon.
double RadianceControl::mu_of(int m, double r) const {
  const double mu_h = horizon_mu(r, R_);
  const double v = static_cast<double>(m) / (res_.view_rows - 1);
  if (v < 0.5) {
    const double d = (0.5 - v) / 0.5;
    return mu_h - (1.0 + mu_h) * d * d;
  }
  const double d = (v - 0.5) / 0.5;
  return mu_h + (1.0 - mu_h) * d * d;
}

double RadianceControl::sun_zenith_of(int s) const { return sun_zenith_lo_ + s * sun_zenith_step_; }

double RadianceControl::cos_azimuth_of(int k) const { return 1.0 - 2.0 * k / (res_.azimuths - 1); }

// Node geometry: p at the node's altitude where the sun's zenith angle is the
// node's; wi at the node's view zenith and azimuth from the sun's.
void RadianceControl::node_geometry(int a, int m, int s, int k, glm::dvec3* p, glm::dvec3* wi) const {
  const double r = R_ + altitude_of(a);
  const SunNodeFrame f = sun_node_frame(sun_, sun_zenith_of(s));
  const glm::dvec3 &up = f.up, &towards_sun = f.towards_sun, &b = f.side;
  const double mu = std::clamp(mu_of(m, r), -1.0, 1.0), sin_view = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  const double cos_phi = cos_azimuth_of(k), sin_phi = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
  *p = r * up;
  *wi = glm::normalize(mu * up + sin_view * (cos_phi * towards_sun + sin_phi * b));
}

RadianceControl::Coordinate RadianceControl::coordinate(double x, int nodes) {
  x = std::clamp(x, 0.0, static_cast<double>(nodes - 1));
  Coordinate c;
  c.i = std::min(static_cast<int>(x), nodes - 2);
  c.f = x - c.i;
  return c;
}

SampledSpectrum RadianceControl::radiance(const glm::dvec3& p, const glm::dvec3& wi,
                                          const SampledWavelengths& lambda) const {
  // --- Table coordinates of (p, wi).
  const double r = glm::length(p);
  const glm::dvec3 up = p / r;
  const double h = std::clamp(r - R_, 0.0, top_);
  const double mu = std::clamp(glm::dot(wi, up), -1.0, 1.0);
  const double mu_s = std::clamp(glm::dot(sun_, up), -1.0, 1.0);
  const double nu = glm::dot(wi, sun_);
  const double den = std::sqrt(std::max(0.0, (1.0 - mu * mu) * (1.0 - mu_s * mu_s)));
  const double cos_phi = den > 1e-9 ? std::clamp((nu - mu * mu_s) / den, -1.0, 1.0) : 1.0;
  const double mu_h = horizon_mu(std::max(r, R_), R_);
  const double v = mu < mu_h ? 0.5 - 0.5 * std::sqrt((mu_h - mu) / (1.0 + mu_h))
                             : 0.5 + 0.5 * std::sqrt((mu - mu_h) / (1.0 - mu_h));
  const Coordinate ca = coordinate(std::sqrt(h / top_) * (res_.altitudes - 1), res_.altitudes);
  const Coordinate cm = coordinate(v * (res_.view_rows - 1), res_.view_rows);
  const Coordinate cs = coordinate((std::acos(mu_s) - sun_zenith_lo_) / sun_zenith_step_, res_.sun_angles);
  const Coordinate ck = coordinate((1.0 - cos_phi) * 0.5 * (res_.azimuths - 1), res_.azimuths);
  // --- Each wavelength between two bin centres.
  std::array<Coordinate, kWavelengthsPerPath> cb;
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    const double x = (lambda.lambda_nm[static_cast<std::size_t>(i)] - lambda_min_) / bin_width_ - 0.5;
    cb[static_cast<std::size_t>(i)] = bins_ > 1 ? coordinate(x, bins_) : Coordinate{0, 0.0};
  }
  // --- Multilinear over the 16 corners.
  SampledSpectrum out(0.0);
  for (int corner = 0; corner < 16; ++corner) {
    const int da = corner & 1, dm = (corner >> 1) & 1, ds = (corner >> 2) & 1, dk = (corner >> 3) & 1;
    const double w = (da ? ca.f : 1.0 - ca.f) * (dm ? cm.f : 1.0 - cm.f) * (ds ? cs.f : 1.0 - cs.f) *
                     (dk ? ck.f : 1.0 - ck.f);
    if (w == 0.0) continue;
    const float* node = &values_[index(ca.i + da, cm.i + dm, cs.i + ds, ck.i + dk)];
    for (int i = 0; i < kWavelengthsPerPath; ++i) {
      const Coordinate& b = cb[static_cast<std::size_t>(i)];
      const double value = bins_ > 1 ? (1.0 - b.f) * node[b.i] + b.f * node[b.i + 1] : node[0];
      out[i] += w * value;
    }
  }
  return out;
}

}  // namespace skyfarm

#include "common/render/shadow_guide.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/lut/lut_sky.h"
#include "common/render/radiance_control.h"

namespace skyfarm {

namespace {

// The cell index of x in [0, 1) over n cells, clamped.
int cell_of(double x, int n) { return std::clamp(static_cast<int>(x * n), 0, n - 1); }

// The interval of a CDF (n + 1 entries, from 0 to 1) holding u.
int interval_of(const double* cdf, int n, double u) {
  const double* it = std::upper_bound(cdf + 1, cdf + n, u);
  return static_cast<int>(it - cdf) - 1;
}

}  // namespace

ShadowGuide::ShadowGuide(const Scene& scene, const ShadowGuideResolution& resolution) : res_(resolution) {
  if (res_.altitudes < 2 || res_.sun_angles < 2 || res_.mu_cells < 2 || res_.phi_cells < 1 || res_.bins < 1 ||
      res_.steps < 1 || !(res_.sun_window_deg > 0.0))
    throw std::invalid_argument("ShadowGuide: every axis needs 2 nodes or cells or more");
  const Atmosphere& atmosphere = scene.atmosphere();
  R_ = atmosphere.planet_radius_m();
  top_ = atmosphere.top_radius_m() - R_;
  sun_ = scene.sun().direction();
  // The sun's zenith angles at the vertices, where it is below their
  // horizontal (covers()).
  const SunZenithWindow window = vertex_sun_zenith_window(scene, res_.sun_window_deg);
  sun_zenith_lo_ = std::max(0.5 * kPi, window.lo);
  sun_zenith_step_ = std::max(1e-6, window.hi - sun_zenith_lo_) / (res_.sun_angles - 1);

  const double range_nm = scene.lambda_max_nm() - scene.lambda_min_nm();
  const int bins = std::clamp(static_cast<int>(range_nm / 20.0), 1, res_.bins);
  const LutSky sky = LutSky::build(atmosphere, scene.sun(), scene.observer_altitude_m(), scene.lambda_min_nm(),
                                   scene.lambda_max_nm(), RadianceControl::lut_resolution(bins));
  const int nodes = res_.altitudes * res_.sun_angles, J = res_.mu_cells, K = res_.phi_cells;
  usable_.assign(static_cast<std::size_t>(nodes), 0);
  density_.assign(static_cast<std::size_t>(nodes) * J * K, 0.0);
  cdf_rows_.assign(static_cast<std::size_t>(nodes) * (J + 1), 0.0);
  cdf_cols_.assign(static_cast<std::size_t>(nodes) * J * (K + 1), 0.0);
  std::vector<double> L(static_cast<std::size_t>(bins));
  for (int a = 0; a < res_.altitudes; ++a) {
    const double u = static_cast<double>(a) / (res_.altitudes - 1);
    const double r = R_ + top_ * u * u;
    for (int s = 0; s < res_.sun_angles; ++s) {
      const int node = a * res_.sun_angles + s;
      const SunNodeFrame f = sun_node_frame(sun_, sun_zenith_lo_ + s * sun_zenith_step_);
      const glm::dvec3 &up = f.up, &towards_sun = f.towards_sun, &side = f.side;
      // --- Cell values: the LUT's radiance at each cell's centre direction.
      double* rows = &cdf_rows_[static_cast<std::size_t>(node) * (J + 1)];
      for (int j = 0; j < J; ++j) {
        const double mu = 0.5 * (mu_edge(j) + mu_edge(j + 1)), sin_view = std::sqrt(std::max(0.0, 1.0 - mu * mu));
        double* cols = &cdf_cols_[(static_cast<std::size_t>(node) * J + static_cast<std::size_t>(j)) * (K + 1)];
        for (int k = 0; k < K; ++k) {
          const double phi = 0.5 * (phi_edge(k) + phi_edge(k + 1));
          const glm::dvec3 wi = glm::normalize(mu * up + sin_view * (std::cos(phi) * towards_sun + std::sin(phi) * side));
          sky.raymarch_radiance(r * up, wi, L, false, res_.steps);
          double value = 0.0;
          for (const double v : L) value += std::isfinite(v) && v > 0.0 ? v : 0.0;
          density_[cell(node, j, k)] = value;
          cols[k + 1] = cols[k] + value * (phi_edge(k + 1) - phi_edge(k));
        }
        rows[j + 1] = rows[j] + cols[K] * (mu_edge(j + 1) - mu_edge(j));
      }
      // --- Normalise: density per steradian over the half sphere, CDFs to 1.
      const double Z = rows[J];
      if (!(Z > 0.0) || !std::isfinite(Z)) continue;
      usable_[static_cast<std::size_t>(node)] = 1;
      for (int j = 0; j < J; ++j) {
        double* cols = &cdf_cols_[(static_cast<std::size_t>(node) * J + static_cast<std::size_t>(j)) * (K + 1)];
        const double row_total = cols[K];
        for (int k = 0; k <= K; ++k) cols[k] = row_total > 0.0 ? cols[k] / row_total : static_cast<double>(k) / K;
        for (int k = 0; k < K; ++k) density_[cell(node, j, k)] /= Z;
      }
      for (int j = 0; j <= J; ++j) rows[j] /= Z;
    }
  }
}

double ShadowGuide::mu_edge(int j) const {
  const double x = 2.0 * j / res_.mu_cells - 1.0;
  return x * std::abs(x);
}

double ShadowGuide::phi_edge(int k) const {
  const double v = static_cast<double>(k) / res_.phi_cells;
  return kPi * v * v;
}

bool ShadowGuide::local_frame(const glm::dvec3& p, SunNodeFrame* f) const {
  f->up = glm::normalize(p);
  const glm::dvec3 t = sun_ - glm::dot(sun_, f->up) * f->up;
  const double len = glm::length(t);
  if (!(len > 1e-9)) return false;
  f->towards_sun = t / len;
  f->side = glm::cross(f->up, f->towards_sun);
  return true;
}

int ShadowGuide::node_of(const glm::dvec3& p) const {
  const double r = glm::length(p);
  const double h = std::clamp(r - R_, 0.0, top_);
  const int a = std::clamp(static_cast<int>(std::lround(std::sqrt(h / top_) * (res_.altitudes - 1))), 0,
                           res_.altitudes - 1);
  const double theta_s = std::acos(std::clamp(glm::dot(sun_, p / r), -1.0, 1.0));
  const int s = std::clamp(static_cast<int>(std::lround((theta_s - sun_zenith_lo_) / sun_zenith_step_)), 0,
                           res_.sun_angles - 1);
  return a * res_.sun_angles + s;
}

bool ShadowGuide::covers(const glm::dvec3& p) const {
  if (!(glm::dot(p, sun_) < 0.0)) return false;
  SunNodeFrame f;
  return local_frame(p, &f) && usable_[static_cast<std::size_t>(node_of(p))];
}

glm::dvec3 ShadowGuide::sample(const glm::dvec3& p, double u1, double u2, double u3) const {
  SunNodeFrame f;
  local_frame(p, &f);
  const int node = node_of(p), J = res_.mu_cells, K = res_.phi_cells;
  // --- A row by its mass, then a cell in it; the remainders place mu and phi.
  const double* rows = &cdf_rows_[static_cast<std::size_t>(node) * (J + 1)];
  const int j = interval_of(rows, J, u1);
  const double tj = std::clamp((u1 - rows[j]) / std::max(rows[j + 1] - rows[j], 1e-300), 0.0, 1.0);
  const double* cols = &cdf_cols_[(static_cast<std::size_t>(node) * J + static_cast<std::size_t>(j)) * (K + 1)];
  const int k = interval_of(cols, K, u2);
  const double tk = std::clamp((u2 - cols[k]) / std::max(cols[k + 1] - cols[k], 1e-300), 0.0, 1.0);
  const double mu = std::clamp(mu_edge(j) + tj * (mu_edge(j + 1) - mu_edge(j)), -1.0, 1.0);
  const double phi = phi_edge(k) + tk * (phi_edge(k + 1) - phi_edge(k));
  const double side = u3 < 0.5 ? 1.0 : -1.0;
  const double sin_view = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  return glm::normalize(mu * f.up + sin_view * (std::cos(phi) * f.towards_sun + side * std::sin(phi) * f.side));
}

double ShadowGuide::pdf(const glm::dvec3& p, const glm::dvec3& wi) const {
  SunNodeFrame f;
  if (!local_frame(p, &f)) return 0.0;
  const int node = node_of(p);
  if (!usable_[static_cast<std::size_t>(node)]) return 0.0;
  const double mu = std::clamp(glm::dot(wi, f.up), -1.0, 1.0);
  const double phi = std::atan2(std::abs(glm::dot(wi, f.side)), glm::dot(wi, f.towards_sun));  // [0, pi]
  const double x = mu < 0.0 ? -std::sqrt(-mu) : std::sqrt(mu);
  const int j = cell_of(0.5 * (x + 1.0), res_.mu_cells);
  const int k = cell_of(std::sqrt(std::max(0.0, phi / kPi)), res_.phi_cells);
  return 0.5 * density_[cell(node, j, k)];  // the coin for the side of the sun's vertical plane
}

}  // namespace skyfarm

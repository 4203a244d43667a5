#include "tests/support/naive_sky_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm::testing {
namespace {

double uniform(std::mt19937_64& rng) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }

// Two unit vectors completing w to a right-handed orthonormal basis (Duff et
// al. 2017, "Building an orthonormal basis, revisited").
void basis(const glm::dvec3& w, glm::dvec3* a, glm::dvec3* b) {
  const double sign = std::copysign(1.0, w.z);
  const double p = -1.0 / (sign + w.z), q = w.x * w.y * p;
  *a = {1.0 + sign * w.x * w.x * p, sign * q, -sign * w.x};
  *b = {q, sign + w.y * w.y * p, -w.y};
}

// A direction in the cone of half-angle acos(cos_max) about w, uniform in
// solid angle: cos theta uniform in [cos_max, 1].
glm::dvec3 sample_cone(const glm::dvec3& w, double cos_max, double u1, double u2) {
  const double c = 1.0 - u1 * (1.0 - cos_max), s = std::sqrt(std::max(0.0, 1.0 - c * c));
  const double phi = 2.0 * kPi * u2;
  glm::dvec3 a, b;
  basis(w, &a, &b);
  return glm::normalize(c * w + s * std::cos(phi) * a + s * std::sin(phi) * b);
}

// Malley's method: a cosine-distributed direction about n.
glm::dvec3 sample_cosine(const glm::dvec3& n, double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  glm::dvec3 a, b;
  basis(n, &a, &b);
  return glm::normalize(r * std::cos(phi) * a + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1.0 - u1)) * n);
}

}  // namespace

NaiveSkyEstimator::NaiveSkyEstimator(const Scene& scene, double lambda_nm)
    : scene_(scene),
      lambda_(lambda_nm),
      R_(scene.atmosphere().planet_radius_m()),
      top_(scene.atmosphere().top_radius_m()) {
  const Sun& sun = scene.sun();
  sun_radiance_ = sun.radiance(lambda_nm);
  cos_alpha_ = std::cos(sun.angular_radius_rad());
  // Omega = 2 pi (1 - cos alpha), written with the half angle to keep its digits.
  const double half = std::sin(0.5 * sun.angular_radius_rad());
  sun_solid_angle_ = sun.is_point() ? 1.0 : 4.0 * kPi * half * half;
  const auto& constituents = scene.atmosphere().constituents();
  const double h_top = scene.atmosphere().top_altitude_m();
  const std::size_t n = static_cast<std::size_t>(std::ceil(h_top / kTableStepM)) + 2;
  table_sigma_t_.assign(n, 0.0);
  table_sigma_s_.assign(constituents.size(), std::vector<double>(n, 0.0));
  for (std::size_t c = 0; c < constituents.size(); ++c) {
    phases_.push_back(constituents[c].phase_at(lambda_nm));
    for (std::size_t i = 0; i < n; ++i) {
      const double h = std::min(static_cast<double>(i) * kTableStepM, h_top);
      table_sigma_s_[c][i] = constituents[c].sigma_s(h, lambda_nm);
      table_sigma_t_[i] += constituents[c].sigma_t(h, lambda_nm);
    }
  }
}

double NaiveSkyEstimator::altitude(const glm::dvec3& p) const { return glm::length(p) - R_; }

NaiveSkyEstimator::Coefficients NaiveSkyEstimator::at(double h) const {
  if (h >= top_ - R_) return {};
  const double x = std::max(0.0, h) / kTableStepM;
  const std::size_t i = std::min(static_cast<std::size_t>(x), table_sigma_t_.size() - 2);
  const double f = x - static_cast<double>(i);
  Coefficients c;
  c.sigma_t = (1.0 - f) * table_sigma_t_[i] + f * table_sigma_t_[i + 1];
  for (std::size_t k = 0; k < table_sigma_s_.size(); ++k) c.sigma_s += sigma_s_of(k, h);
  return c;
}

double NaiveSkyEstimator::sigma_s_of(std::size_t k, double h) const {
  if (h >= top_ - R_) return 0.0;
  const double x = std::max(0.0, h) / kTableStepM;
  const std::size_t i = std::min(static_cast<std::size_t>(x), table_sigma_t_.size() - 2);
  const double f = x - static_cast<double>(i);
  return (1.0 - f) * table_sigma_s_[k][i] + f * table_sigma_s_[k][i + 1];
}

// The altitude changes along d at the rate cos(local zenith) = d . p / |p|;
// the step keeps that change under 20 m + 1 % of the altitude (the air's
// scale height grows with altitude and the thin air matters less) and the
// step under 5 km (near a tangent point the altitude changes by s^2 / 2r:
// 2 m over 5 km).
double NaiveSkyEstimator::step_length(const glm::dvec3& p, const glm::dvec3& d) const {
  const double r = glm::length(p);
  const double dh = 20.0 + 0.01 * std::max(0.0, r - R_);
  const double rate = std::abs(glm::dot(p, d)) / r;
  return std::min(5000.0, dh / std::max(rate, 1e-9));
}

double NaiveSkyEstimator::segment_end(const Ray& ray, bool* ground) const {
  *ground = false;
  const double r = glm::length(ray.o);
  double t0 = 0.0;
  if (r > top_) {
    const SphereHit hit = intersect_sphere(ray, top_);
    if (!hit.hit || hit.t_near < 0.0) return -1.0;
    t0 = hit.t_near;
  }
  const double tg = ground_distance(ray, R_);
  if (tg >= 0.0) {
    *ground = true;
    return tg;
  }
  const SphereHit hit = intersect_sphere(ray, top_);
  return hit.hit ? std::max(hit.t_far, t0) : t0;
}

double NaiveSkyEstimator::optical_depth(const Ray& ray, double t_end) const {
  bool ground = false;
  const double t_exit = segment_end(ray, &ground);
  if (t_exit <= 0.0) return 0.0;
  const double t_max = std::min(t_end, t_exit);
  double tau = 0.0;
  for (double t = 0.0; t < t_max;) {
    const double ds = std::min(step_length(ray.at(t), ray.d), t_max - t);
    tau += at(altitude(ray.at(t + 0.5 * ds))).sigma_t * ds;
    t += ds;
  }
  return tau;
}

double NaiveSkyEstimator::sun_transmittance(const glm::dvec3& p, const glm::dvec3& w) const {
  const Ray ray{p, w};
  if (ground_distance(ray, R_) >= 0.0) return 0.0;
  return std::exp(-optical_depth(ray, 1e300));
}

double NaiveSkyEstimator::mixture_phase(double h, double mu) const {
  double sum = 0.0, weighted = 0.0;
  for (std::size_t k = 0; k < phases_.size(); ++k) {
    const double s = sigma_s_of(k, h);
    sum += s;
    if (s > 0.0) weighted += s * phases_[k].eval(mu);
  }
  return sum > 0.0 ? weighted / sum : 0.0;
}

glm::dvec3 NaiveSkyEstimator::sample_sun_direction(std::mt19937_64& rng) const {
  const double u1 = uniform(rng), u2 = uniform(rng);
  if (scene_.sun().is_point()) return scene_.sun().direction();
  return sample_cone(scene_.sun().direction(), cos_alpha_, u1, u2);
}

// NEE with a direction uniform in the disk (pdf 1 / Omega):
// L_sun Omega p(mu) T, mu between the sunlight's propagation -w and the
// scattered light's -d_in.
double NaiveSkyEstimator::sun_at_medium_vertex(const glm::dvec3& p, const glm::dvec3& d_in,
                                               std::mt19937_64& rng) const {
  const glm::dvec3 w = sample_sun_direction(rng);
  const double T = sun_transmittance(p, w);
  if (T <= 0.0) return 0.0;
  return sun_radiance_ * sun_solid_angle_ * mixture_phase(altitude(p), glm::dot(w, d_in)) * T;
}

double NaiveSkyEstimator::sun_at_ground(const glm::dvec3& p, const glm::dvec3& n, std::mt19937_64& rng) const {
  const glm::dvec3 w = sample_sun_direction(rng);
  const double cos_theta = glm::dot(w, n);
  if (cos_theta <= 0.0) return 0.0;
  const double T = sun_transmittance(p, w);
  return sun_radiance_ * sun_solid_angle_ * scene_.atmosphere().ground().albedo(lambda_) * kInvPi * cos_theta * T;
}

double NaiveSkyEstimator::sample(const Ray& camera, std::mt19937_64& rng, int max_order) const {
  const double albedo = scene_.atmosphere().ground().albedo(lambda_);
  Ray ray = camera;
  double L = 0.0;
  for (int order = 0; order < max_order; ++order) {
    bool ground = false;
    const double t_end = segment_end(ray, &ground);
    if (t_end < 0.0) return L;  // misses the atmosphere (and the planet)
    // Analog free flight: march until the optical depth passes -ln(1 - u).
    double target = -std::log(1.0 - uniform(rng));
    double t = 0.0;
    bool collided = false;
    // A ray from outside starts marching where it enters.
    if (glm::length(ray.o) > top_) t = intersect_sphere(ray, top_).t_near;
    while (t < t_end) {
      const double ds = std::min(step_length(ray.at(t), ray.d), t_end - t);
      const double sigma_t = at(altitude(ray.at(t + 0.5 * ds))).sigma_t;
      const double dtau = sigma_t * ds;
      if (dtau >= target) {
        t += target / sigma_t;
        collided = true;
        break;
      }
      target -= dtau;
      t += ds;
    }
    if (collided) {
      const glm::dvec3 p = ray.at(t);
      const double h = altitude(p);
      const Coefficients c = at(h);
      if (uniform(rng) * c.sigma_t >= c.sigma_s) return L;  // absorbed
      L += sun_at_medium_vertex(p, ray.d, rng);
      // Which constituent scatters, then its phase function.
      double pick = uniform(rng) * c.sigma_s;
      std::size_t k = 0;
      for (; k + 1 < phases_.size(); ++k) {
        pick -= sigma_s_of(k, h);
        if (pick < 0.0) break;
      }
      const double u1 = uniform(rng), u2 = uniform(rng);
      ray = Ray{p, phases_[k].sample_direction(ray.d, u1, u2)};
      continue;
    }
    if (!ground) return L;  // left the atmosphere
    // The ground: lifted 1 cm off the surface so that the next ray starts above it.
    const glm::dvec3 n = glm::normalize(ray.at(t_end));
    const glm::dvec3 p = n * (R_ + 0.01);
    L += sun_at_ground(p, n, rng);
    if (uniform(rng) >= albedo) return L;
    const double u1 = uniform(rng), u2 = uniform(rng);
    ray = Ray{p, sample_cosine(n, u1, u2)};
  }
  return L;
}

NaiveEstimate NaiveSkyEstimator::estimate(const Ray& ray, int paths, std::uint64_t seed, int max_order) const {
  std::mt19937_64 rng(seed);
  return estimate_mean(paths, [&](int) { return sample(ray, rng, max_order); });
}

// L1 = int_0^s_max T(0, s) sigma_s(s) p(mu) E T_sun(s) ds, by the midpoint
// rule on steps of at most max_step_m; T(0, s) accumulated step by step.
double NaiveSkyEstimator::single_scattering(const Ray& ray, double max_step_m) const {
  bool ground = false;
  const double t_end = segment_end(ray, &ground);
  if (t_end <= 0.0) return 0.0;
  const glm::dvec3 w = scene_.sun().direction();
  const double mu = glm::dot(w, ray.d);
  const double E = scene_.sun().is_point() ? sun_radiance_ : sun_radiance_ * sun_solid_angle_;
  double L = 0.0, tau = 0.0;
  for (double t = 0.0; t < t_end;) {
    const double ds = std::min({step_length(ray.at(t), ray.d), max_step_m, t_end - t});
    const glm::dvec3 p = ray.at(t + 0.5 * ds);
    const double h = altitude(p);
    const Coefficients c = at(h);
    // Transmittance to the step's midpoint: tau so far plus half the step.
    const double T = std::exp(-(tau + 0.5 * c.sigma_t * ds));
    if (c.sigma_s > 0.0) L += T * c.sigma_s * mixture_phase(h, mu) * E * sun_transmittance(p, w) * ds;
    tau += c.sigma_t * ds;
    t += ds;
  }
  return L;
}

}  // namespace skyfarm::testing

#include "common/clouds/scene_clouds.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skyfarm {
namespace {

// Ratio tracking's estimate below this plays Russian roulette: it survives
// with probability T / kRouletteBelow and then carries kRouletteBelow.
constexpr double kRouletteBelow = 0.1;

}  // namespace

SceneClouds::SceneClouds(std::vector<std::shared_ptr<const CloudField>> fields) : fields_(std::move(fields)) {
  bottom_m_ = std::numeric_limits<double>::infinity();
  top_m_ = -std::numeric_limits<double>::infinity();
  for (const auto& f : fields_) {
    bottom_m_ = std::min(bottom_m_, f->bottom_altitude_m());
    top_m_ = std::max(top_m_, f->top_altitude_m());
  }
  if (fields_.empty()) bottom_m_ = top_m_ = 0.0;
}

// Delta tracking, field by field: each field's first real collision is
// searched only before the nearest found so far (the later ones could not be
// the first of the sum).
std::optional<SceneClouds::Collision> SceneClouds::sample_collision(const Ray& ray, double t_begin, double t_end,
                                                                    Sampler& sampler,
                                                                    std::uint64_t* collisions) const {
  std::optional<Collision> nearest;
  double t_limit = t_end;
  for (const auto& field : fields_) {
    std::optional<double> found;
    field->for_each_majorant(ray, t_begin, t_limit, [&](double t0, double t1, double sigma_maj) {
      if (!(sigma_maj > 0.0)) return true;
      double t = t0;
      while (true) {
        t -= std::log1p(-sampler.next()) / sigma_maj;
        if (!(t < t1)) return true;
        ++*collisions;
        const double sigma = field->sigma_t(ray.at(t));
        if (sampler.next() * sigma_maj < sigma) {
          found = t;
          return false;
        }
      }
    });
    if (found) {
      nearest = Collision{*found, field.get()};
      t_limit = *found;
    }
  }
  return nearest;
}

double SceneClouds::transmittance(const Ray& ray, double t_begin, double t_end, Sampler& sampler,
                                  std::uint64_t* collisions) const {
  double T = 1.0;
  for (const auto& field : fields_) {
    field->for_each_majorant(ray, t_begin, t_end, [&](double t0, double t1, double sigma_maj) {
      if (!(sigma_maj > 0.0)) return true;
      double t = t0;
      while (true) {
        t -= std::log1p(-sampler.next()) / sigma_maj;
        if (!(t < t1)) return true;
        ++*collisions;
        T *= std::max(0.0, 1.0 - field->sigma_t(ray.at(t)) / sigma_maj);
        if (T < kRouletteBelow) {
          if (!(T > 0.0) || sampler.next() * kRouletteBelow >= T) {
            T = 0.0;
            return false;
          }
          T = kRouletteBelow;
        }
      }
    });
    if (!(T > 0.0)) return 0.0;
  }
  return T;
}

double SceneClouds::optical_depth(const Ray& ray, double t_begin, double t_end, double step_m) const {
  double tau = 0.0;
  for (const auto& field : fields_) {
    field->for_each_majorant(ray, t_begin, t_end, [&](double t0, double t1, double) {
      const int n = std::max(1, static_cast<int>(std::ceil((t1 - t0) / step_m)));
      const double dt = (t1 - t0) / n;
      for (int i = 0; i < n; ++i) tau += field->sigma_t(ray.at(t0 + (i + 0.5) * dt)) * dt;
      return true;
    });
  }
  return tau;
}

}  // namespace skyfarm

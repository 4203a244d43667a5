#include "common/render/scene.h"

#include "common/atmosphere/atmosphere_builder.h"

namespace skyfarm {

Scene::Scene(Atmosphere atmosphere, Sun sun, double observer_altitude_m, double lambda_min_nm, double lambda_max_nm)
    : atmosphere_(std::make_unique<Atmosphere>(std::move(atmosphere))),
      medium_(std::make_unique<AtmosphereMedium>(*atmosphere_, lambda_min_nm, lambda_max_nm)),
      sun_(std::move(sun)),
      observer_(0.0, 0.0, atmosphere_->planet_radius_m() + observer_altitude_m),
      lambda_min_(lambda_min_nm),
      lambda_max_(lambda_max_nm) {}

Scene Scene::from_specs(const AtmosphereSpec& atmosphere, const SunSpec& sun, const Location& location,
                        const std::optional<UtcInstant>& time, double lambda_min_nm, double lambda_max_nm) {
  Scene scene(build_atmosphere(atmosphere), Sun::from_spec(sun, location, time), location.altitude_m, lambda_min_nm,
              lambda_max_nm);
  if (atmosphere.ground_material) {
    auto surface = std::make_shared<const material::Surface>(*atmosphere.ground_material);
    // A Lambertian material is all its albedo: the atmosphere's ground already is it.
    if (!surface->lambertian()) scene.ground_surface_ = std::move(surface);
  }
  if (atmosphere.refraction)
    scene.refraction_ = AtmosphereRefraction::shared(atmosphere.planet_radius_m, atmosphere.top_altitude_m);
  return scene;
}

}  // namespace skyfarm

// Everything a path needs to know about the world: the atmosphere and its
// tracking structures, the sun, the observer, and the spectral range.
//
// Parameters (built from a request's specs by Scene::from_specs):
//   atmosphere            planet, shell, constituents, ground (Lambertian: its albedo)
//   ground_surface        the ground's material when it is not Lambertian
//                         (null otherwise: a plain ground pays nothing new)
//   objects               surfaces in the air (null: none, and none of their cost)
//   clouds                cloud layers and volumes (null: a clear sky, which
//                         takes exactly the code it always took)
//   sun                   position, disk, irradiance
//   observer_altitude_m   the camera / probe position above the ground (on +z)
//   lambda_min/max_nm     the wavelengths paths may carry (majorants cover them)
//   environment_radiance  uniform radiance arriving from beyond the atmosphere,
//                         W m^-2 sr^-1 nm^-1 (0 in real skies; the furnace tests use it)
//   sun_enabled           false removes the sun (furnace tests)
//   refraction            rays bend in the air (atmosphere_refraction.h),
//                         or null: straight rays, and none of the cost
#pragma once
#include <memory>
#include <optional>

#include <glm/vec3.hpp>

#include "common/atmosphere/atmosphere.h"
#include "common/atmosphere/atmosphere_spec.h"
#include "common/clouds/scene_clouds.h"
#include "common/material/surface.h"
#include "common/render/atmosphere_medium.h"
#include "common/render/atmosphere_refraction.h"
#include "common/render/scene_objects.h"
#include "common/sun/sun.h"

namespace skyfarm {

class Scene {
 public:
  Scene(Atmosphere atmosphere, Sun sun, double observer_altitude_m, double lambda_min_nm, double lambda_max_nm);
  static Scene from_specs(const AtmosphereSpec& atmosphere, const SunSpec& sun, const Location& location,
                          const std::optional<UtcInstant>& time, double lambda_min_nm, double lambda_max_nm);

  const Atmosphere& atmosphere() const { return *atmosphere_; }
  const AtmosphereMedium& medium() const { return *medium_; }
  const Sun& sun() const { return sun_; }
  // The ground's BSDF when it is not Lambertian, else null.
  const material::Surface* ground_surface() const { return ground_surface_.get(); }
  // The objects in the scene, or null.
  const SceneObjects* objects() const { return objects_.get(); }
  void set_objects(std::shared_ptr<const SceneObjects> objects) { objects_ = std::move(objects); }
  // The clouds in the scene, or null.
  const SceneClouds* clouds() const { return clouds_.get(); }
  void set_clouds(std::shared_ptr<const SceneClouds> clouds) { clouds_ = std::move(clouds); }
  // The bending of rays in the air ("atmosphere.refraction"), or null.
  const AtmosphereRefraction* refraction() const { return refraction_.get(); }
  void set_refraction(std::shared_ptr<const AtmosphereRefraction> refraction) { refraction_ = std::move(refraction); }
  // Planet-centred observer position (0, 0, R + altitude).
  glm::dvec3 observer() const { return observer_; }
  double observer_altitude_m() const { return observer_.z - atmosphere_->planet_radius_m(); }
  double lambda_min_nm() const { return lambda_min_; }
  double lambda_max_nm() const { return lambda_max_; }

  double environment_radiance = 0.0;
  bool sun_enabled = true;

 private:
  std::unique_ptr<Atmosphere> atmosphere_;
  std::unique_ptr<AtmosphereMedium> medium_;
  std::shared_ptr<const material::Surface> ground_surface_;
  std::shared_ptr<const SceneObjects> objects_;
  std::shared_ptr<const SceneClouds> clouds_;
  std::shared_ptr<const AtmosphereRefraction> refraction_;
  Sun sun_;
  glm::dvec3 observer_;
  double lambda_min_, lambda_max_;
};

}  // namespace skyfarm

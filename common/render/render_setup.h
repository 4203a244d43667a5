// What renders a render: from the renderer's spec of it (RenderSpec: the
// scene's specs, the camera, the wavelengths and samples) to the scene
// (atmosphere, sun, observer, majorants), the camera and the render plan.
// Shared by the local renderer, the benchmarks and the farm, so all of them
// cut a render into the same units of work and pick the same estimators.
//
// The plan's policy lives here: square tiles of 32 pixels and 16 samples per
// pass; the LUT renderer one sample per pixel and batch in one pass;
// path-traced plans use the roulette's control variate and the shadow guide
// where they pay (render_plan.h), adaptive sample allocation when asked and
// the plan has two passes or more, and the pooled ground for an observer at
// exactly 0 m.
//
// The spec holds no request: api/render_spec.h translates a validated render
// request into one.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "common/atmosphere/atmosphere_spec.h"
#include "common/camera/camera.h"
#include "common/camera/camera_spec.h"
#include "common/clouds/cloud_spec.h"
#include "common/objects/object_spec.h"
#include "common/film/error_estimate.h"
#include "common/film/image.h"
#include "common/render/render_plan.h"
#include "common/render/scene.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

struct RenderSpec {
  // The scene (Scene::from_specs).
  Location location;
  std::optional<UtcInstant> time;
  SunSpec sun;
  AtmosphereSpec atmosphere;
  std::vector<ObjectSpec> objects;  // none: the plain sky, no BVH built
  CloudsSpec clouds;                // none: a clear sky, nothing built for clouds
  // The view, the wavelengths and the samples.
  CameraSpec camera;
  double lambda_min_nm = 360.0, lambda_max_nm = 830.0;
  int batches = 1;               // equal wavelength batches of [lambda_min_nm, lambda_max_nm]
  int samples_per_pixel = 64;    // path-traced renders (the LUT renderer takes 1)
  bool adaptive = false;         // variance-aware sample allocation after a pilot pass
  bool lut = false;              // the LUT renderer instead of the path tracer
  std::uint64_t seed = 1;
};

struct RenderSetup {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Camera> camera;
  RenderPlan plan;
};

namespace assets {
class MeshSource;
class VolumeSource;
}  // namespace assets
// `meshes` resolves the mesh objects' asset ids, `volumes` the cloud
// volumes'; either may be null for a spec without them (one with them then
// throws std::runtime_error).
RenderSetup make_render_setup(const RenderSpec& spec, const assets::MeshSource* meshes = nullptr,
                              const assets::VolumeSource* volumes = nullptr);

// The clouds of a spec on a planet of this radius, or null for a clear sky.
std::shared_ptr<const SceneClouds> make_scene_clouds(const RenderSpec& spec, double planet_radius_m,
                                                     const assets::VolumeSource* volumes);

// The plan of a render (tiles, batches, passes, mirror symmetry), given its sun.
RenderPlan render_plan_for(const RenderSpec& spec, const Sun& sun);

// The metadata every rendered image carries (EXR attributes, PNG text), the
// same for `skyfarm-worker render` and the farm so their files are identical:
// the canonical request text, sun position, samples, wavelength range,
// version, method and the estimated error.
void set_render_metadata(Image* image, std::string_view canonical_request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error);

}  // namespace skyfarm

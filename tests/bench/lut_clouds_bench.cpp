// Frame time of the LUT renderer with clouds (common/lut/cloud_march.h)
// against the clear sky, one thread, tables built outside the timing.
//
//   BM_LutCloudsFrame/0   clear sky
//   BM_LutCloudsFrame/1   a uniform slab, 1-2 km, vertical tau 10 (overcast)
//   BM_LutCloudsFrame/2   the cumulus preset layer (cloud_layer_preset)
//
// Frame: 256 x 256 fisheye, 180 deg, looking straight up (every pixel sees
// the sky, most of them the clouds), observer on the ground, sun at 40 deg,
// Earth preset, one batch over 360-830 nm.  Report medians
// (--benchmark_repetitions=5 --benchmark_report_aggregates_only=true); a
// case whose clouds this build cannot make is skipped with its reason.
#include <benchmark/benchmark.h>

#include <memory>
#include <stdexcept>

#include "common/clouds/uniform_cloud_slab.h"
#include "common/film/image.h"
#include "common/render/local_render.h"
#include "common/render/render_setup.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {
namespace {

RenderSpec frame_spec() {
  RenderSpec spec;
  spec.sun.zenith_deg = 40.0;
  spec.sun.azimuth_deg = 180.0;
  spec.camera.projection = Projection::kFisheye;
  spec.camera.width = 256;
  spec.camera.height = 256;
  spec.camera.pitch_deg = 90.0;
  spec.camera.fov_deg = 180.0;
  spec.lut = true;
  return spec;
}

void BM_LutCloudsFrame(benchmark::State& state) {
  RenderSpec spec = frame_spec();
  const int scene = static_cast<int>(state.range(0));
  if (scene == 2) spec.clouds.layers.push_back(cloud_layer_preset(CloudType::kCumulus));
  RenderSetup setup;
  try {
    setup = make_render_setup(spec);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  if (scene == 1) {
    CloudOptics optics;
    optics.phase = PhaseFunction::henyey_greenstein(0.85);
    optics.asymmetry = 0.85;
    setup.scene->set_clouds(std::make_shared<SceneClouds>(std::vector<std::shared_ptr<const CloudField>>{
        std::make_shared<UniformCloudSlab>(setup.scene->atmosphere().planet_radius_m(), 1000.0, 2000.0, 0.01,
                                           optics)}));
  }
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  for (auto _ : state) {
    Image image(setup.plan.width, setup.plan.height, ImageLayers{});
    render_image(renderer, &image, 1);
    benchmark::DoNotOptimize(image.luminance(128, 128));
  }
}
BENCHMARK(BM_LutCloudsFrame)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace skyfarm

#include "common/render/tile_renderer.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "common/lut/cloud_march.h"
#include "common/lut/lut_sky.h"
#include "common/lut/spectral_grid.h"
#include "common/render/radiance_control.h"
#include "common/render/shadow_guide.h"
#include "common/render/sun_pixels.h"
#include "common/spectrum/color.h"

namespace skyfarm {

namespace {

// The caller's options, with the roulette control and the shadow guide built
// when the plan asks for them and the caller gave none.
IntegratorOptions with_plan_tables(const Scene& scene, const RenderPlan& plan, IntegratorOptions options) {
  if (plan.roulette_control && !plan.lut && !options.roulette_control)
    options.roulette_control = std::make_shared<const RadianceControl>(scene);
  if (plan.shadow_guide && !plan.lut && !options.shadow_guide)
    options.shadow_guide = std::make_shared<const ShadowGuide>(scene);
  return options;
}

}  // namespace

TileRenderer::TileRenderer(const Scene& scene, const Camera& camera, const RenderPlan& plan,
                           IntegratorOptions options)
    : scene_(scene), camera_(camera), plan_(plan), integrator_(scene, with_plan_tables(scene, plan, options)),
      sun_pixels_(skyfarm::sun_pixels(camera, scene.sun(), scene.refraction(), scene.observer())) {
  if (plan_.lut) {
    LutSky sky = LutSky::build(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(), plan_.lambda_min_nm,
                               plan_.lambda_max_nm);
    lut_ = std::make_shared<const LutSky>(scene.refraction() ? sky.refracted() : std::move(sky));
  }
  build_lut_clouds({});
}

TileRenderer::TileRenderer(const Scene& scene, const Camera& camera, const RenderPlan& plan,
                           std::shared_ptr<const LutSky> lut, const CloudMarchOptions& clouds)
    : scene_(scene), camera_(camera), plan_(plan), integrator_(scene), sun_pixels_(skyfarm::sun_pixels(camera, scene.sun(), scene.refraction(), scene.observer())),
      lut_(std::move(lut)) {
  plan_.lut = true;
  build_lut_clouds(clouds);
}

void TileRenderer::build_lut_clouds(const CloudMarchOptions& options) {
  if (lut_ && scene_.clouds()) cloud_march_ = std::make_shared<const CloudMarch>(*lut_, *scene_.clouds(), options);
}

// One LUT sample per pixel: the centre's radiance, or for pixels that see
// the sun disk the mean of kSub x kSub sub-pixel directions (the disk is
// 0.27 deg across, often less than a pixel: a centre sample would hit or
// miss it whole).
void TileRenderer::render_unit_lut(const WorkUnit& unit, FilmTile* film) const {
  constexpr int kSub = 8;
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(unit.tile, &x0, &y0, &w, &h);
  const BinnedSpectrumIntegral band(lut_->grid(), plan_.batch_min_nm(unit.batch), plan_.batch_max_nm(unit.batch));
  const std::size_t n = static_cast<std::size_t>(lut_->grid().size());
  std::vector<double> L(n), L_sub(n);
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      if (!camera_.pixel_exists(x, y)) continue;
      const std::uint32_t pixel = static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(plan_.width) +
                                  static_cast<std::uint32_t>(x);
      const bool sees_sun = std::binary_search(sun_pixels_.begin(), sun_pixels_.end(), pixel);
      Ray ray;
      if (!sees_sun) {
        if (!camera_.generate_ray(x, y, 0.5, 0.5, &ray)) continue;
        lut_->radiance(ray.d, L, true);
        if (cloud_march_) cloud_march_->composite(ray.d, L);
      } else {
        std::fill(L.begin(), L.end(), 0.0);
        int count = 0;
        for (int j = 0; j < kSub; ++j)
          for (int i = 0; i < kSub; ++i) {
            if (!camera_.generate_ray(x, y, (i + 0.5) / kSub, (j + 0.5) / kSub, &ray)) continue;
            lut_->radiance(ray.d, L_sub, true);
            if (cloud_march_) cloud_march_->composite(ray.d, L_sub);
            for (std::size_t k = 0; k < n; ++k) L[k] += L_sub[k];
            ++count;
          }
        if (count == 0) continue;
        for (double& v : L) v /= count;
      }
      film->add_sample(x, y, unit.batch, band.xyz(L), band.band_mean(L));
    }
  }
}

FilmTile TileRenderer::empty_tile(int tile) const {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(tile, &x0, &y0, &w, &h);
  return FilmTile(x0, y0, w, h, plan_.batches);
}

void TileRenderer::render_unit(const WorkUnit& unit, FilmTile* film, PathCounters* counters) const {
  if (lut_) {
    render_unit_lut(unit, film);
    return;
  }
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(unit.tile, &x0, &y0, &w, &h);
  const double l0 = plan_.batch_min_nm(unit.batch), l1 = plan_.batch_max_nm(unit.batch);
  const VisibleWavelengthSampler wavelengths(l0, l1);
  const std::uint64_t seed = plan_.batch_seed(unit.batch);
  const double band_width = l1 - l0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      if (!camera_.pixel_exists(x, y)) continue;
      const std::uint64_t pixel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(plan_.width) +
                                  static_cast<std::uint64_t>(x);
      int first = 0, end = 0;
      plan_.sample_range(unit, x, y, &first, &end);
      for (int s = first; s < end; ++s) {
        Sampler sampler(seed, pixel, static_cast<std::uint64_t>(s));
        const double jx = sampler.next(), jy = sampler.next();
        Ray ray;
        if (!camera_.generate_ray(x, y, jx, jy, &ray)) continue;
        const SampledWavelengths lambda = wavelengths.sample_wavelengths(sampler.next());
        const SampledSpectrum L = integrator_.radiance(ray, lambda, sampler, counters);
        // Band mean radiance: (1 / band width) mean_i L_i / pdf_i.
        double band = 0.0;
        for (int i = 0; i < kWavelengthsPerPath; ++i) band += L[i] / lambda.pdf[static_cast<std::size_t>(i)];
        band /= kWavelengthsPerPath * band_width;
        film->add_sample(x, y, unit.batch, spectral_sample_to_xyz(lambda, L.v), band);
      }
    }
  }
}

FilmTile TileRenderer::render_tile(int tile, PathCounters* counters) const {
  if (plan_.adaptive)
    throw std::logic_error("render_tile: an adaptive plan's passes after the pilot need the whole frame's pilot "
                           "(render_image_progressive)");
  FilmTile total = empty_tile(tile);
  for (int p = 0; p < plan_.passes; ++p) {
    FilmTile pass = empty_tile(tile);
    for (int b = 0; b < plan_.batches; ++b) render_unit({tile, b, p}, &pass, counters);
    total.merge(pass);
  }
  return total;
}

}  // namespace skyfarm

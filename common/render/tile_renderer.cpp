#include "common/render/tile_renderer.h"

#include "common/render/sun_pixels.h"
#include "common/spectrum/color.h"

namespace skyfarm {

TileRenderer::TileRenderer(const Scene& scene, const Camera& camera, const RenderPlan& plan,
                           IntegratorOptions options)
    : scene_(scene), camera_(camera), plan_(plan), integrator_(scene, options), sun_pixels_(skyfarm::sun_pixels(camera, scene.sun())) {}

FilmTile TileRenderer::empty_tile(int tile) const {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(tile, &x0, &y0, &w, &h);
  return FilmTile(x0, y0, w, h, plan_.batches);
}

void TileRenderer::render_unit(const WorkUnit& unit, FilmTile* film, PathCounters* counters) const {
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
      for (int s = plan_.pass_first_sample(unit.pass); s < plan_.pass_end_sample(unit.pass); ++s) {
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
  FilmTile total = empty_tile(tile);
  for (int p = 0; p < plan_.passes; ++p) {
    FilmTile pass = empty_tile(tile);
    for (int b = 0; b < plan_.batches; ++b) render_unit({tile, b, p}, &pass, counters);
    total.merge(pass);
  }
  return total;
}

}  // namespace skyfarm

#include "server/jobs/unit_result_check.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/ray.h"
#include "common/sampling/sampler.h"

namespace skyfarm::server {
namespace {

std::string pixel_text(int x, int y, int batch) {
  return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") of batch " + std::to_string(batch);
}

bool finite_and_signed_right(const PixelBatchSums& s) {
  for (double v : {s.n, s.sum_x, s.sum_y, s.sum_z, s.sum_y2, s.sum_l, s.sum_r2, s.sum_g2, s.sum_b2})
    if (!std::isfinite(v)) return false;
  // Counts and sums of squares cannot be negative.
  return s.n >= 0.0 && s.sum_y2 >= 0.0 && s.sum_r2 >= 0.0 && s.sum_g2 >= 0.0 && s.sum_b2 >= 0.0;
}

bool all_zero(const PixelBatchSums& s) {
  return s.n == 0.0 && s.sum_x == 0.0 && s.sum_y == 0.0 && s.sum_z == 0.0 && s.sum_y2 == 0.0 && s.sum_l == 0.0 &&
         s.sum_r2 == 0.0 && s.sum_g2 == 0.0 && s.sum_b2 == 0.0;
}

}  // namespace

UnitResultCheck::UnitResultCheck(const RenderPlan& plan, const Camera& camera, std::vector<std::uint32_t> sun_pixels)
    : plan_(plan), camera_(camera), sun_pixels_(std::move(sun_pixels)) {}

// The image circle is convex: when the corners of the pixel grown by a pixel
// on every side have directions, every jittered point of the pixel has one,
// with a margin no rounding of the circle test can cross.
bool UnitResultCheck::whole_pixel_has_directions(int x, int y) const {
  if (camera_.projection() != Projection::kFisheye) return true;
  Ray ray;
  for (double jy : {-1.0, 2.0})
    for (double jx : {-1.0, 2.0})
      if (!camera_.generate_ray(x, y, jx, jy, &ray)) return false;
  return true;
}

int UnitResultCheck::expected_samples(const WorkUnit& unit, int x, int y) const {
  if (!camera_.pixel_exists(x, y)) return 0;
  Ray ray;
  if (plan_.lut) {
    // TileRenderer::render_unit_lut.
    const std::uint32_t pixel = static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(plan_.width) +
                                static_cast<std::uint32_t>(x);
    if (!std::binary_search(sun_pixels_.begin(), sun_pixels_.end(), pixel))
      return camera_.generate_ray(x, y, 0.5, 0.5, &ray) ? 1 : 0;
    constexpr int kSub = 8;
    for (int j = 0; j < kSub; ++j)
      for (int i = 0; i < kSub; ++i)
        if (camera_.generate_ray(x, y, (i + 0.5) / kSub, (j + 0.5) / kSub, &ray)) return 1;
    return 0;
  }
  int first = 0, end = 0;
  plan_.sample_range(unit, x, y, &first, &end);
  if (end <= first) return 0;
  if (whole_pixel_has_directions(x, y)) return end - first;
  // TileRenderer::render_unit: the jitter is the sample's first two numbers.
  const std::uint64_t seed = plan_.batch_seed(unit.batch);
  const std::uint64_t pixel =
      static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(plan_.width) + static_cast<std::uint64_t>(x);
  int n = 0;
  for (int s = first; s < end; ++s) {
    Sampler sampler(seed, pixel, static_cast<std::uint64_t>(s));
    const double jx = sampler.next(), jy = sampler.next();
    if (camera_.generate_ray(x, y, jx, jy, &ray)) ++n;
  }
  return n;
}

std::string UnitResultCheck::check(const WorkUnit& unit, const FilmTile& film) const {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(unit.tile, &x0, &y0, &w, &h);
  if (film.x0() != x0 || film.y0() != y0 || film.width() != w || film.height() != h ||
      film.batches() != plan_.batches)
    return "the result is a " + std::to_string(film.width()) + " x " + std::to_string(film.height()) + " tile at (" +
           std::to_string(film.x0()) + ", " + std::to_string(film.y0()) + ") with " + std::to_string(film.batches()) +
           " batches; tile " + std::to_string(unit.tile) + " is " + std::to_string(w) + " x " + std::to_string(h) +
           " at (" + std::to_string(x0) + ", " + std::to_string(y0) + ") with " + std::to_string(plan_.batches);
  if (unit.batch < 0 || unit.batch >= plan_.batches) return "batch " + std::to_string(unit.batch) + " is not in the plan";
  const std::uint64_t rejected = film.rejected_samples();
  std::uint64_t missing = 0;
  for (int b = 0; b < plan_.batches; ++b) {
    for (int y = y0; y < y0 + h; ++y) {
      for (int x = x0; x < x0 + w; ++x) {
        const PixelBatchSums& s = film.sums(x, y, b);
        if (!finite_and_signed_right(s)) return pixel_text(x, y, b) + " has a non-finite or negative sum";
        if (s.n == 0.0) {
          if (!all_zero(s)) return pixel_text(x, y, b) + " has sums without samples";
          if (b != unit.batch) continue;
        } else if (b != unit.batch) {
          return pixel_text(x, y, b) + " has samples, but the unit renders batch " + std::to_string(unit.batch);
        }
        const int expected = expected_samples(unit, x, y);
        if (s.n > expected || s.n != std::floor(s.n))
          return pixel_text(x, y, b) + " has " + std::to_string(s.n) + " samples; the unit asks for " +
                 std::to_string(expected);
        missing += static_cast<std::uint64_t>(expected - static_cast<int>(s.n));
        if (missing > rejected)
          return pixel_text(x, y, b) + " has " + std::to_string(static_cast<int>(s.n)) +
                 " samples; the unit asks for " + std::to_string(expected) + " (and the tile rejected " +
                 std::to_string(rejected) + " non-finite samples in all)";
      }
    }
  }
  if (missing != rejected)
    return "the tile reports " + std::to_string(rejected) + " rejected samples but lacks " + std::to_string(missing);
  return "";
}

}  // namespace skyfarm::server

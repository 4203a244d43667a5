#include "server/jobs/disk_budget.h"

#include <system_error>

#include "api/render_request.h"
#include "common/film/film_tile.h"

namespace skyfarm::server {
namespace {

constexpr std::int64_t kFileHeaderSlack = 64 * 1024;

// OpenEXR: R, G, B (half or float), a float per spectral band, a float error
// layer; per 16-line ZIP chunk an offset (8 bytes) and a chunk header (8).
std::int64_t exr_bytes(const api::RenderRequest& request, const RenderPlan& plan) {
  const auto& out = request.output;
  const std::int64_t per_pixel = 3 * (out.half ? 2 : 4) + (out.spectral_channels ? 4 * plan.batches : 0) +
                                 (out.error_layer ? 4 : 0);
  const std::int64_t chunks = (plan.height + 15) / 16;
  return static_cast<std::int64_t>(plan.width) * plan.height * per_pixel + chunks * 16 + kFileHeaderSlack;
}

// PNG: at most 16-bit RGB plus a filter byte per row, deflate's stored-block
// overhead (5 bytes per 64 KiB).
std::int64_t png_bytes(const RenderPlan& plan) {
  const std::int64_t raw = static_cast<std::int64_t>(plan.height) * (static_cast<std::int64_t>(plan.width) * 6 + 1);
  return raw + (raw / 65535 + 1) * 5 + kFileHeaderSlack;
}

}  // namespace

std::int64_t tile_file_bytes(const RenderPlan& plan, int tile) {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan.tile_rect(tile, &x0, &y0, &w, &h);
  constexpr std::int64_t kMergerHeader = 12, kFilmHeader = 40, kCrc = 4;
  return kMergerHeader + kFilmHeader + plan.batches +
         static_cast<std::int64_t>(w) * h * plan.batches * static_cast<std::int64_t>(sizeof(PixelBatchSums)) + kCrc;
}

std::int64_t estimated_job_bytes(const api::RenderRequest& request, const RenderPlan& plan) {
  std::int64_t tiles = 0;
  for (int t = 0; t < plan.tile_count(); ++t) tiles += tile_file_bytes(plan, t);
  const std::int64_t request_text = static_cast<std::int64_t>(api::canonical_text(request).size());
  const std::int64_t image = exr_bytes(request, plan) + png_bytes(plan) + 4 * request_text;
  return tiles + 2 * image + 2 * kFileHeaderSlack;  // two of each image at once; report and allocation
}

std::int64_t directory_bytes(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::int64_t total = 0;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    std::error_code e;
    if (it->is_regular_file(e)) {
      const auto size = it->file_size(e);
      if (!e) total += static_cast<std::int64_t>(size);
    }
  }
  return total;
}

std::int64_t default_disk_budget(const std::filesystem::path& data_dir) {
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(data_dir, ec);
  const std::int64_t free_bytes = ec ? 0 : static_cast<std::int64_t>(space.available);
  return free_bytes / 5 * 4 + directory_bytes(data_dir);
}

}  // namespace skyfarm::server

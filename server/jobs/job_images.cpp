#include "server/jobs/job_images.h"

#include "api/render_spec.h"
#include "common/image/atomic_file.h"
#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace fs = std::filesystem;

void write_snapshot(const ImageSnapshot& snap) {
  try {
    write_exr(snap.image, snap.dir / (snap.stem + ".exr"), snap.exr);
    write_png(snap.image, snap.dir / (snap.stem + ".png"), snap.png);
  } catch (const FileWriteError& e) {
    throw StorageError(e.what());
  }
}

void remove_preview(const fs::path& dir, int units) {
  std::error_code ec;
  for (const char* ext : {".exr", ".png"}) fs::remove(dir / ("preview-" + std::to_string(units) + ext), ec);
}

// Resolves the merged tiles into an image and writes EXR and PNG next to the
// job's tiles: image.* when final, preview.* while running (atomic renames,
// so readers of an older preview keep a complete file).
ImageSnapshot snapshot_images(Job& job, bool final) {
  const auto& out = job.request.output;
  ImageLayers layers;
  if (out.spectral_channels)
    layers.spectral = SpectralLayout{job.plan.lambda_min_nm, job.plan.lambda_max_nm, job.plan.batches};
  layers.relative_error = out.error_layer;
  ImageSnapshot snap{Image(job.plan.width, job.plan.height, layers), job.dir,
                     final ? "image" : "preview-" + std::to_string(job.merger->merged_units()), {}, {}};
  job.merger->resolve(&snap.image);
  const Sun sun = Sun::from_spec(job.request.sun, job.request.location, job.request.time);
  api::set_render_metadata(&snap.image, job.request, job.plan, sun,
                           job.mean_samples_per_pixel(job.merger->complete_passes()),
                           job.merger->error_sums(job.sun_pixels));
  snap.exr.half = out.half;
  snap.exr.spectral_channels = out.spectral_channels;
  snap.exr.error_layer = out.error_layer;
  snap.exr.latlong_envmap = job.request.camera.projection == Projection::kEquirectangular;
  snap.exr.color_space = out.color_space;
  snap.exr.units = out.units;
  snap.exr.exposure_ev = out.exposure_ev;
  snap.png.exposure_ev = out.exposure_ev;
  snap.png.view = out.view;
  return snap;
}

// The final image (at finish and on resume), under the lock.
void write_images(Job& job, bool final) {
  write_snapshot(snapshot_images(job, final));
  // Previews are versioned by the units they hold, so a file and its ETag
  // always agree; the previous one is removed (open readers keep its inode).
  if (job.preview_units >= 0 && job.preview_units != job.merger->merged_units())
    remove_preview(job.dir, job.preview_units);
}

}  // namespace skyfarm::server

// A job's images: its merged sums resolved into an image and written as EXR
// and PNG next to its tiles, image.* when final, preview-<units>.* while it
// runs (versioned by the units they hold, so a file and its ETag always
// agree).  Resolving needs the job book's lock; encoding and writing
// (write_snapshot) does not, so a large image never holds up dispatch.
#pragma once
#include <filesystem>
#include <string>

#include "common/image/exr_writer.h"
#include "common/film/image.h"
#include "common/image/png_writer.h"
#include "server/jobs/job.h"

namespace skyfarm::server {

// A job's image at one moment, ready to be encoded and stored: dir/stem.exr|png.
struct ImageSnapshot {
  Image image;
  std::filesystem::path dir;
  std::string stem;
  ExrWriteOptions exr;
  PngWriteOptions png;
};

// Encodes and stores a snapshot (atomic renames); throws StorageError.
void write_snapshot(const ImageSnapshot& snap);
// Removes the preview that held `units` merged units.
void remove_preview(const std::filesystem::path& dir, int units);
// The job's image now, resolved from its merged sums (under the lock).
ImageSnapshot snapshot_images(Job& job, bool final);
// The final image (at finish and on resume), written at once, under the lock.
void write_images(Job& job, bool final);

}  // namespace skyfarm::server

// The data directory's disk budget: what a job will write, what a directory
// holds, and the budget a server gets when none is given.
//
// A job writes (job_service.h, tile_merger.h), in data_dir/jobs/<id>/:
//   tile_<t>.bin   per tile: the merger's 12-byte header, then the FilmTile
//                  (film_tile.h: 40-byte header, a flag per batch, width x
//                  height x batches records of 9 doubles, a 4-byte CRC);
//   image.exr, image.png, and while it runs one preview of each (versioned,
//   the previous removed after the next is written, the last after the final
//   image is): at most two of each at once;
//   report.json, allocation.json: small.
// estimated_job_bytes bounds these from above: tiles exactly, the EXR as if
// stored uncompressed (OpenEXR keeps a chunk uncompressed when compression
// does not pay), the PNG as unfiltered 16-bit RGB, plus the request text
// twice (image metadata) and 64 KiB of headers per file.
#pragma once
#include <cstdint>
#include <filesystem>

#include "api/render_request.h"
#include "common/render/render_plan.h"

namespace skyfarm::server {

// The bytes of one tile file of tile t at its final size.
std::int64_t tile_file_bytes(const RenderPlan& plan, int tile);
// An upper bound of the bytes a job writes (see the file comment).
std::int64_t estimated_job_bytes(const api::RenderRequest& request, const RenderPlan& plan);
// The bytes of the regular files under `dir` (0 when it does not exist).
std::int64_t directory_bytes(const std::filesystem::path& dir);
// The budget sized to the machine at start: 80 % of the space free on the
// data directory's filesystem plus what the directory already holds.
std::int64_t default_disk_budget(const std::filesystem::path& data_dir);

}  // namespace skyfarm::server

// Import of an OpenVDB file's float grid into a VolumeGrid (volume_grid.h).
//
//   bytes      the .vdb file (OpenVDB's stream form: detect by the magic
//              0x56444220, " BDV" read as a little-endian int32, at offset 0)
//   grid_name  the float grid to take; an empty name takes "density", else
//              the only float grid of a file that has exactly one
//   limits     VolumeLimits (volume_file.h): the dense box's voxel count and bytes
//
// The grid is made dense over its active voxels' bounding box (inactive
// voxels inside it hold the background value), every value clamped to a
// finite number >= 0 (NaN and infinities become 0).  Index to metres comes
// from the grid's transform, whose units are taken as metres; it must be
// linear and axis-aligned with positive scales (a scale-translate map; a
// rotated, sheared, mirrored, perspective (frustum) transform is refused, so
// that a voxel is a box along the grid's axes).
//
// OpenVDB is a large parser of hostile input that may throw or abort on a
// malformed file: the server runs this in a child process
// (server/assets/volume_import_process.h), never in its own.
#pragma once
#include <string>
#include <string_view>

#include "common/assets/volume_file.h"
#include "common/assets/volume_grid.h"

namespace skyfarm::assets {

// The first four bytes of every OpenVDB file.
bool looks_like_vdb(std::string_view bytes);

// The grid, or false with `error` (one sentence for a client) set.
bool import_vdb(std::string_view bytes, std::string_view grid_name, const VolumeLimits& limits, VolumeGrid* grid,
                std::string* error);

}  // namespace skyfarm::assets

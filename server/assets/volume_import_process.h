// Runs the OpenVDB import (common/assets/vdb_import.h) in a child process
// (import_child.h): OpenVDB may throw, abort or allocate without bound on a
// malformed file, and that must cost the upload, never the server.
//
//   command, work_dir, timeout, cpu_seconds, memory_bytes   as import_child.h;
//                the command is e.g. {"/proc/self/exe", "import-volume"}
//                (skyfarm-server's own mode, run_import_volume_command
//                below); the child gets
//                --grid NAME --max-voxels N --max-bytes N IN OUT
//   limits       the dense grid's voxel and byte limits (volume_file.h)
//
// The parent trusts nothing the child writes: the SKYVOL1 output is decoded
// strictly (decode_volume_file).
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "common/assets/volume_file.h"
#include "common/assets/volume_grid.h"
#include "server/assets/import_child.h"

namespace skyfarm::server {

struct VolumeImportOptions : ImportChildOptions {
  assets::VolumeLimits limits;
};

struct VolumeImportResult {
  bool ok = false;
  assets::VolumeGrid grid;  // when ok
  std::string file;         // its SKYVOL1 bytes, when ok
  std::string error;        // one sentence for the client, when not ok
};

// `grid_name` as import_vdb (empty: "density", else the file's only float grid).
VolumeImportResult run_volume_import(std::string_view bytes, std::string_view grid_name,
                                     const VolumeImportOptions& options);

// The child's side: `import-volume [--grid NAME] [--max-voxels N] [--max-bytes N] IN OUT`.
// Exit 0 with OUT written, 1 with the reason on stderr, 2 for a usage error.
int run_import_volume_command(const std::vector<std::string>& args);

}  // namespace skyfarm::server

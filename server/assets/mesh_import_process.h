// Runs the mesh import (common/assets/mesh_import.h) in a child process
// (import_child.h), so that a crash, a hang or a memory blow-up of the
// parser costs the upload, never the server.
//
//   command, work_dir, timeout, cpu_seconds, memory_bytes   as import_child.h;
//                the command is e.g. {"/proc/self/exe", "import-mesh"}
//                (skyfarm-server's own mode, run_import_mesh_command below);
//                the child gets --format F --max-triangles N --max-vertices N IN OUT
//   limits       the mesh's triangle and vertex limits
//
// The parent trusts nothing the child writes: the output is decoded strictly
// (decode_mesh_file) and canonicalized again.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/assets/mesh_file.h"
#include "common/assets/triangle_mesh.h"
#include "server/assets/import_child.h"

namespace skyfarm::server {

struct MeshImportOptions : ImportChildOptions {
  assets::MeshLimits limits;
};

struct MeshImportResult {
  bool ok = false;
  assets::TriangleMesh mesh;  // canonical, when ok
  std::string error;          // one sentence for the client, when not ok
};

MeshImportResult run_mesh_import(std::string_view bytes, std::string_view format, const MeshImportOptions& options);

// The child's side: `import-mesh --format F --max-triangles N --max-vertices N IN OUT`.
// Exit 0 with OUT written, 1 with the reason on stderr, 2 for a usage error.
int run_import_mesh_command(const std::vector<std::string>& args);

}  // namespace skyfarm::server

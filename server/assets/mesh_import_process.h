// Runs the mesh import (common/assets/mesh_import.h) in a child process, so
// that a crash, a hang or a memory blow-up of the parser costs the upload,
// never the server.
//
//   command      the child's program and first arguments, e.g.
//                {"/proc/self/exe", "import-mesh"} (skyfarm-server's own mode,
//                run_import_mesh_command below); the child gets
//                --format F --max-triangles N --max-vertices N IN OUT
//   work_dir     where the input, output and stderr files live meanwhile
//                (one fresh directory per import, removed after)
//   timeout      wall clock; the child is killed (SIGKILL) beyond
//   cpu_seconds  RLIMIT_CPU of the child
//   memory_bytes RLIMIT_AS of the child (address space, so it bounds what
//                assimp can allocate)
//   limits       the mesh's triangle and vertex limits
//
// The parent trusts nothing the child writes: the output is decoded strictly
// (decode_mesh_file) and canonicalized again.  fork() is followed only by
// async-signal-safe calls (dup2, setrlimit, close_range, chdir, execv).
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/assets/mesh_file.h"
#include "common/assets/triangle_mesh.h"

namespace skyfarm::server {

struct MeshImportOptions {
  std::vector<std::string> command;
  std::string work_dir;
  std::chrono::milliseconds timeout = std::chrono::seconds(30);
  unsigned cpu_seconds = 20;
  std::uint64_t memory_bytes = std::uint64_t{4} << 30;
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

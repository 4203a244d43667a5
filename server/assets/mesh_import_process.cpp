#include "server/assets/mesh_import_process.h"

#include <iostream>
#include <string>

#include "common/assets/mesh_import.h"

namespace skyfarm::server {

MeshImportResult run_mesh_import(std::string_view bytes, std::string_view format, const MeshImportOptions& options) {
  MeshImportResult result;
  ImportChildResult child = run_import_child(
      bytes,
      {"--format", std::string(format), "--max-triangles", std::to_string(options.limits.max_triangles),
       "--max-vertices", std::to_string(options.limits.max_vertices)},
      options, "mesh");
  if (!child.ok) {
    result.error = std::move(child.error);
    return result;
  }
  const std::string& mesh_bytes = child.output;
  assets::TriangleMesh mesh;
  if (!assets::decode_mesh_file(mesh_bytes, options.limits, &mesh, &result.error)) {
    result.error = "the mesh importer's output is invalid: " + result.error;
    return result;
  }
  result.mesh = assets::canonicalize_mesh(mesh);
  if (result.mesh.triangle_count() == 0) {
    result.error = "the file has no triangles of non-zero area";
    return result;
  }
  result.ok = true;
  return result;
}

int run_import_mesh_command(const std::vector<std::string>& args) {
  std::string format, in, out;
  assets::MeshLimits limits;
  const std::vector<ImportOption> options = {
      {"--format",
       [&](const std::string& v) {
         format = v;
         return true;
       }},
      {"--max-triangles", [&](const std::string& v) { return parse_count(v, &limits.max_triangles); }},
      {"--max-vertices", [&](const std::string& v) { return parse_count(v, &limits.max_vertices); }},
  };
  if (const int status = parse_import_args(args, "import-mesh", options, &in, &out); status != 0) return status;
  if (format.empty() || in.empty() || out.empty()) {
    std::cerr << "usage: import-mesh --format F [--max-triangles N] [--max-vertices N] IN OUT\n";
    return 2;
  }
  std::string bytes;
  if (!read_whole_file(in, &bytes)) {
    std::cerr << "import-mesh: cannot read " << in << "\n";
    return 2;
  }
  assets::TriangleMesh mesh;
  std::string error;
  if (!assets::import_mesh(bytes, format, limits, &mesh, &error)) {
    std::cerr << error << "\n";
    return 1;
  }
  if (!write_whole_file(out, assets::encode_mesh_file(mesh))) {
    std::cerr << "import-mesh: cannot write " << out << "\n";
    return 1;
  }
  return 0;
}

}  // namespace skyfarm::server

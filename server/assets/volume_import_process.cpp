#include "server/assets/volume_import_process.h"

#include <iostream>
#include <string>

#include "common/assets/vdb_import.h"

namespace skyfarm::server {

VolumeImportResult run_volume_import(std::string_view bytes, std::string_view grid_name,
                                     const VolumeImportOptions& options) {
  VolumeImportResult result;
  ImportChildResult child = run_import_child(
      bytes,
      {"--grid", std::string(grid_name), "--max-voxels", std::to_string(options.limits.max_voxels), "--max-bytes",
       std::to_string(options.limits.max_bytes)},
      options, "volume");
  if (!child.ok) {
    result.error = std::move(child.error);
    return result;
  }
  if (!assets::decode_volume_file(child.output, options.limits, &result.grid, &result.error)) {
    result.error = "the volume importer's output is invalid: " + result.error;
    return result;
  }
  result.file = std::move(child.output);
  result.ok = true;
  return result;
}

int run_import_volume_command(const std::vector<std::string>& args) {
  std::string grid, in, out;
  assets::VolumeLimits limits;
  const std::vector<ImportOption> options = {
      {"--grid",
       [&](const std::string& v) {
         grid = v;
         return true;
       }},
      {"--max-voxels", [&](const std::string& v) { return parse_count(v, &limits.max_voxels); }},
      {"--max-bytes", [&](const std::string& v) { return parse_count(v, &limits.max_bytes); }},
  };
  if (const int status = parse_import_args(args, "import-volume", options, &in, &out); status != 0) return status;
  if (in.empty() || out.empty()) {
    std::cerr << "usage: import-volume [--grid NAME] [--max-voxels N] [--max-bytes N] IN OUT\n";
    return 2;
  }
  std::string bytes;
  if (!read_whole_file(in, &bytes)) {
    std::cerr << "import-volume: cannot read " << in << "\n";
    return 2;
  }
  assets::VolumeGrid grid_out;
  std::string error;
  if (!assets::import_vdb(bytes, grid, limits, &grid_out, &error)) {
    std::cerr << error << "\n";
    return 1;
  }
  if (!write_whole_file(out, assets::encode_volume_file(grid_out))) {
    std::cerr << "import-volume: cannot write " << out << "\n";
    return 1;
  }
  return 0;
}

}  // namespace skyfarm::server

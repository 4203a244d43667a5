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
  auto number = [](const std::string& s, std::uint64_t* value) {
    try {
      std::size_t used = 0;
      *value = std::stoull(s, &used);
      return used == s.size();
    } catch (const std::exception&) {
      return false;
    }
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if (a == "--grid" && has_value) {
      grid = args[++i];
    } else if (a == "--max-voxels" && has_value) {
      if (!number(args[++i], &limits.max_voxels)) return 2;
    } else if (a == "--max-bytes" && has_value) {
      if (!number(args[++i], &limits.max_bytes)) return 2;
    } else if (in.empty()) {
      in = a;
    } else if (out.empty()) {
      out = a;
    } else {
      std::cerr << "import-volume: unexpected argument '" << a << "'\n";
      return 2;
    }
  }
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

// The content-addressed store of mesh assets in the data directory:
//
//   <data_dir>/assets/<hex>.mesh   the imported mesh, canonical (mesh_file.h)
//   <data_dir>/assets/<hex>.json   its metadata, written after the mesh: an
//                                  asset exists when both do
//   <data_dir>/assets/tmp/         imports in progress (mesh_import_process.h)
//
// The id is "sha256:<hex>", the SHA-256 of the canonical mesh file, not of
// the uploaded bytes: the same triangles uploaded as OBJ or as PLY are one
// asset, and anyone holding the .mesh file (a worker, later) can check it
// against its id.  Files are written to a temporary name and renamed, so a
// reader never sees half a file and concurrent uploads of one mesh agree.
//
// Options: `max_upload_bytes` (the HTTP body limit of an upload),
// `max_concurrent_imports` (children at once; more uploads wait their turn,
// so that N uploads cannot ask for N x memory_bytes) and `import` (the child
// process, its limits; work_dir is set here, and emptied at start: what is
// there is left from a server that stopped mid-import).
#pragma once
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "common/assets/asset_id.h"
#include "server/assets/mesh_import_process.h"

namespace skyfarm::server {

struct AssetStoreOptions {
  std::size_t max_upload_bytes = 64u << 20;
  int max_concurrent_imports = 2;
  MeshImportOptions import;
};

struct AssetPut {
  bool ok = false;
  bool created = false;   // false: the asset was already stored
  nlohmann::json meta;    // {"id", "triangles", "vertices", "bounds": {"min": [x,y,z], "max": [...]}, "bytes"}
  std::string error;      // when not ok: why the file is not a usable mesh
};

class AssetStore {
 public:
  AssetStore(const std::string& data_dir, AssetStoreOptions options);

  // Imports `bytes` of `format` (kMeshFormats) and stores the mesh.  Throws
  // std::runtime_error when the store itself fails (disk, importer missing).
  AssetPut put(std::string_view bytes, std::string_view format);

  // The metadata of a stored asset, or nullopt (unknown, or a malformed id).
  std::optional<nlohmann::json> meta(std::string_view id) const;
  // The path of its .mesh file, or nullopt.
  std::optional<std::string> mesh_path(std::string_view id) const;
  // The bytes of its .mesh file (what a worker fetches), or nullopt.  Throws
  // std::runtime_error when the file exists but cannot be read.
  std::optional<std::string> mesh_file(std::string_view id) const;

  const AssetStoreOptions& options() const { return options_; }

 private:
  std::string dir_;
  AssetStoreOptions options_;
  std::mutex mutex_;
  std::condition_variable turn_;
  int importing_ = 0;
};

// The ids' rules live with the renderer (common/assets/asset_id.h): workers check them too.
using assets::is_asset_id;
using assets::sha256_hex;

}  // namespace skyfarm::server

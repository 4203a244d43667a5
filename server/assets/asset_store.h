// The content-addressed store of mesh and cloud volume assets in the data
// directory:
//
//   <data_dir>/assets/<hex>.mesh   an imported mesh, canonical (mesh_file.h)
//   <data_dir>/assets/<hex>.vol    an imported cloud volume (volume_file.h)
//   <data_dir>/assets/<hex>.json   its metadata, written after the mesh or
//                                  volume: an asset exists when both do
//   <data_dir>/assets/tmp/         imports in progress (mesh_import_process.h,
//                                  volume_import_process.h)
//
// The id is "sha256:<hex>", the SHA-256 of the canonical mesh (or volume) file, not of
// the uploaded bytes: the same triangles uploaded as OBJ or as PLY are one
// asset, and anyone holding the .mesh file (a worker, later) can check it
// against its id.  Files are written to a temporary name and renamed, so a
// reader never sees half a file and concurrent uploads of one mesh agree.
//
// Options: `max_upload_bytes` (the HTTP body limit of an upload),
// `max_concurrent_imports` (children at once; more uploads wait their turn,
// so that N uploads cannot ask for N x memory_bytes), `import` and
// `volume_import` (the child processes, their limits; work_dir is set here,
// and emptied at start: what is there is left from a server that stopped
// mid-import).
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
#include "server/assets/volume_import_process.h"

namespace skyfarm::server {

struct AssetStoreOptions {
  std::size_t max_upload_bytes = 64u << 20;
  int max_concurrent_imports = 2;
  MeshImportOptions import;
  VolumeImportOptions volume_import;
};

struct AssetPut {
  bool ok = false;
  bool created = false;   // false: the asset was already stored
  // a mesh: {"id", "triangles", "vertices", "bounds": {"min": [x,y,z], "max": [...]}, "bytes"}
  // a volume: {"id", "kind": "volume", "voxels": [nx,ny,nz], "voxel_size_m": [x,y,z],
  //            "bounds": {"min", "max"} (the voxel centres' box, metres), "max_value", "bytes"}
  nlohmann::json meta;
  std::string error;      // when not ok: why the file is not a usable mesh (volume)
};

class AssetStore {
 public:
  AssetStore(const std::string& data_dir, AssetStoreOptions options);

  // Imports `bytes` of `format` (kMeshFormats) and stores the mesh.  Throws
  // std::runtime_error when the store itself fails (disk, importer missing).
  AssetPut put(std::string_view bytes, std::string_view format);
  // Imports the OpenVDB file `bytes` (its float grid `grid_name`, empty: as
  // import_vdb) and stores the volume.  Throws as put().
  AssetPut put_volume(std::string_view bytes, std::string_view grid_name);

  // The metadata of a stored asset, or nullopt (unknown, or a malformed id).
  std::optional<nlohmann::json> meta(std::string_view id) const;
  // The path of its .mesh file, or nullopt.
  std::optional<std::string> mesh_path(std::string_view id) const;
  // The bytes of its .mesh file (what a worker fetches), or nullopt.  Throws
  // std::runtime_error when the file exists but cannot be read.
  std::optional<std::string> mesh_file(std::string_view id) const;
  // The same of a volume's .vol file.
  std::optional<std::string> volume_path(std::string_view id) const;
  std::optional<std::string> volume_file(std::string_view id) const;
  // Whether the asset is a stored volume (its metadata says "kind": "volume").
  bool is_volume(std::string_view id) const;
  // The file a worker fetches for this id, mesh or volume (ASSET_GET), or nullopt.
  std::optional<std::string> asset_file(std::string_view id) const;

  const AssetStoreOptions& options() const { return options_; }

 private:
  // Waits for a free import slot; the returned guard gives it back.
  class ImportTurn;
  // Writes the file and its metadata unless both are there; sets put.created.
  void store(const std::string& hex, std::string_view extension, std::string_view file, AssetPut* put);
  std::optional<std::string> read_file(std::string_view id, std::string_view extension) const;

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

// Mesh assets of `skyfarm-worker render REQUEST.json`: the request's
// "objects" may name a mesh by file path where the farm takes an asset id.
//
// resolve_request_assets() rewrites the request before it is parsed: each
// objects[i].asset that is not an asset id ("sha256:<64 hex>") is a file
// (relative to `base_dir`, or absolute), imported here with the farm's
// importer (format from the extension, else guessed from the bytes),
// canonicalized and named by the SHA-256 of its mesh file, so the request's
// canonical text, hash, seed and metadata are those the farm would have for
// the same mesh uploaded.  An asset that is an id must be in the disk cache
// the farm worker keeps (worker/asset_cache.h).  The returned source serves
// the imported meshes, then the cached ones.
//
// Cloud volumes likewise (resolve_request_volumes): each
// clouds.volumes[i].asset that is not an asset id is an OpenVDB file (its
// float grid clouds.volumes[i].grid, default "density") or a SKYVOL1 file,
// imported here and named by the SHA-256 of its SKYVOL1 file, as the farm's
// upload would.
//
// Errors name the field: "objects[2].asset: cannot read foo.obj: ..." (all
// of them at once, as an api::ValidationError).  A request that is not JSON,
// or whose objects are malformed, is left for the request parser to refuse.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "common/assets/mesh_source.h"
#include "common/assets/volume_source.h"
#include "worker/asset_cache.h"
#include "worker/mesh_cache.h"
#include "worker/volume_cache.h"

namespace skyfarm {

// The meshes of one local render: imported files, then the disk cache.
class LocalMeshSource : public assets::MeshSource {
 public:
  explicit LocalMeshSource(AssetDiskCache* disk) : cache_(disk, {}) {}
  std::shared_ptr<const assets::TriangleMesh> mesh(std::string_view id) const override;
  void add(const std::string& id, std::shared_ptr<const assets::TriangleMesh> mesh) { imported_[id] = std::move(mesh); }

 private:
  std::map<std::string, std::shared_ptr<const assets::TriangleMesh>, std::less<>> imported_;
  MeshCache cache_;
};

// The volumes of one local render: imported files, then the disk cache.
class LocalVolumeSource : public assets::VolumeSource {
 public:
  explicit LocalVolumeSource(AssetDiskCache* disk) : cache_(disk, {}) {}
  std::shared_ptr<const assets::VolumeGrid> volume(std::string_view id) const override;
  void add(const std::string& id, std::shared_ptr<const assets::VolumeGrid> grid) { imported_[id] = std::move(grid); }

 private:
  std::map<std::string, std::shared_ptr<const assets::VolumeGrid>, std::less<>> imported_;
  VolumeCache cache_;
};

// Rewrites *request as above; throws api::ValidationError.
std::unique_ptr<LocalMeshSource> resolve_request_assets(nlohmann::json* request, const std::string& base_dir,
                                                        AssetDiskCache* disk);
std::unique_ptr<LocalVolumeSource> resolve_request_volumes(nlohmann::json* request, const std::string& base_dir,
                                                           AssetDiskCache* disk);

}  // namespace skyfarm

// The worker's MeshSource (common/assets/mesh_source.h): the meshes a job's
// objects name by asset id, from memory, else the disk cache
// (worker/asset_cache.h), else `fetch` (the farm worker asks the server,
// worker/asset_requests.h).  Bytes from the disk or the server are used only
// if they hash to the id and decode as a mesh file within the MeshLimits;
// fetched bytes are then written to the disk cache.
//
// Parameters
//   disk          the disk cache, or null (none)
//   fetch         the file's bytes by id; throws std::runtime_error (with a
//                 sentence) when it cannot have them; AssetUnavailable when
//                 asking again later may work (no answer, no connection).
//                 Empty: an asset found neither in memory nor on disk is an
//                 error that says to upload it or give a file path
//   memory_bytes  the bound on the decoded meshes kept in memory (least
//                 recently used go first; a mesh a setup still holds lives on
//                 in it)
//
// Threads: mesh() may be called from every render thread; an asset wanted by
// several at once is loaded (and fetched) once, the others wait for it.
// Errors are not remembered: the next call tries again.
//
// The machinery (memory, disk, fetch, the hash check) is worker/decoded_asset_cache.h.
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "common/assets/mesh_file.h"
#include "common/assets/mesh_source.h"
#include "worker/asset_cache.h"
#include "worker/decoded_asset_cache.h"

namespace skyfarm {

// An asset that could not be had now but may be later (the server did not
// answer): a unit's setup that failed so is not cached (worker/setup_cache.h).
class AssetUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using MeshCacheStats = AssetCacheStats;

class MeshCache : public assets::MeshSource {
 public:
  using Fetch = std::function<std::string(const std::string& id)>;

  MeshCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes = std::size_t{1} << 30,
            assets::MeshLimits limits = {});

  std::shared_ptr<const assets::TriangleMesh> mesh(std::string_view id) const override;

  MeshCacheStats stats() const;

 private:
  DecodedAssetCache<assets::TriangleMesh> cache_;
};

// The bytes a decoded mesh holds (its positions and indices).
std::size_t mesh_bytes(const assets::TriangleMesh& mesh);

}  // namespace skyfarm

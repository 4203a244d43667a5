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
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

#include "common/assets/mesh_file.h"
#include "common/assets/mesh_source.h"
#include "worker/asset_cache.h"

namespace skyfarm {

// An asset that could not be had now but may be later (the server did not
// answer): a unit's setup that failed so is not cached (worker/setup_cache.h).
class AssetUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MeshCacheStats {
  std::uint64_t memory_hits = 0;
  std::uint64_t disk_hits = 0;
  std::uint64_t fetches = 0;   // calls of fetch
  std::uint64_t rejected = 0;  // files that did not hash to their id or did not decode
};

class MeshCache : public assets::MeshSource {
 public:
  using Fetch = std::function<std::string(const std::string& id)>;

  MeshCache(AssetDiskCache* disk, Fetch fetch, std::size_t memory_bytes = std::size_t{1} << 30,
            assets::MeshLimits limits = {});

  std::shared_ptr<const assets::TriangleMesh> mesh(std::string_view id) const override;

  MeshCacheStats stats() const;

 private:
  using Mesh = std::shared_ptr<const assets::TriangleMesh>;
  Mesh load(const std::string& id) const;
  // The mesh in `bytes`, or null with *why set.
  Mesh decode(const std::string& id, const std::string& bytes, std::string* why) const;
  void remember(const std::string& id, const Mesh& mesh) const;

  AssetDiskCache* disk_;
  Fetch fetch_;
  std::size_t memory_bytes_;
  assets::MeshLimits limits_;
  mutable std::mutex mutex_;
  mutable std::list<std::pair<std::string, Mesh>> lru_;  // most recent first
  mutable std::size_t held_bytes_ = 0;
  mutable std::map<std::string, std::shared_future<Mesh>> loading_;
  mutable std::atomic<std::uint64_t> memory_hits_{0}, disk_hits_{0}, fetches_{0}, rejected_{0};
};

// The bytes a decoded mesh holds (its positions and indices).
std::size_t mesh_bytes(const assets::TriangleMesh& mesh);

}  // namespace skyfarm

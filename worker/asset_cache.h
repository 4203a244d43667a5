// A worker's disk cache of mesh assets: <dir>/<hex>.mesh, the canonical mesh
// file (common/assets/mesh_file.h) of the asset "sha256:<hex>", so a worker
// that restarts, or a second worker on the same machine, does not fetch it
// again.  `skyfarm-worker render` looks there too.  A cloud volume's SKYVOL1
// file (common/assets/volume_file.h) is kept under the same name: the id
// names the bytes, whichever kind they are, and the caches that read them
// (mesh_cache.h, volume_cache.h) check both the hash and the format.
//
// Parameters
//   dir        the folder (created on the first write); the farm worker's
//              --asset-cache, default default_asset_cache_dir()
//   max_bytes  the bound on the files' total size (--asset-cache-mb, 2048 MB):
//              after a write, the least recently used files are removed
//              until the rest fit (the file just written stays, even alone
//              over the bound)
//
// Files are written to a temporary name and renamed, so a reader (another
// process included) never sees half a file; a read marks the file used (its
// modification time).  Nothing here trusts the files: whoever reads one
// checks it against its id (worker/mesh_cache.h).  Thread-safe.
#pragma once
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

namespace skyfarm {

class AssetDiskCache {
 public:
  AssetDiskCache(std::string dir, std::size_t max_bytes);

  const std::string& dir() const { return dir_; }
  std::size_t max_bytes() const { return max_bytes_; }
  // The path of an asset's file (whether or not it exists).
  std::string path(std::string_view id) const;
  // The file's bytes, or nullopt (absent, unreadable, or not an asset id).
  std::optional<std::string> read(std::string_view id) const;
  // Stores the file, then evicts.  Throws std::runtime_error when it cannot write.
  void write(std::string_view id, std::string_view bytes);
  // Removes an asset's file (one that did not match its id).
  void remove(std::string_view id);

 private:
  void evict(const std::string& keep);

  std::string dir_;
  std::size_t max_bytes_;
  mutable std::mutex mutex_;
};

// $CACHE_DIRECTORY/assets (systemd's
// CacheDirectory=); else $XDG_CACHE_HOME/skyfarm/assets or
// $HOME/.cache/skyfarm/assets where HOME is writable; else
// ${TMPDIR:-/tmp}/skyfarm-worker-<uid>/assets.
std::string default_asset_cache_dir();

}  // namespace skyfarm

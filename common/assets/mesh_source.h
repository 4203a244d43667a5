// Where the renderer gets the meshes a scene's objects name by asset id
// ("sha256:<hex>"): the server's store, a worker's cache that fetches over
// the wire, or the files `skyfarm-worker render` imported.  A scene without
// mesh objects never asks.
#pragma once

#include <memory>
#include <string_view>

#include "common/assets/triangle_mesh.h"

namespace skyfarm::assets {

class MeshSource {
 public:
  virtual ~MeshSource() = default;
  // The mesh with this id, never null.  Throws std::runtime_error with a
  // sentence naming the id when it cannot be had (unknown, unreachable, or
  // its bytes do not hash to the id).  May be called from many threads.
  virtual std::shared_ptr<const TriangleMesh> mesh(std::string_view id) const = 0;
};

}  // namespace skyfarm::assets

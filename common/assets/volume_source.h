// Where the renderer gets the cloud volumes a scene names by asset id
// ("sha256:<hex>"): the server's store, a worker's cache that fetches over
// the wire, or the files `skyfarm-worker render` imported.  A scene without
// cloud volumes never asks.
#pragma once

#include <memory>
#include <string_view>

#include "common/assets/volume_grid.h"

namespace skyfarm::assets {

class VolumeSource {
 public:
  virtual ~VolumeSource() = default;
  // The grid with this id, never null.  Throws std::runtime_error with a
  // sentence naming the id when it cannot be had.  May be called from many threads.
  virtual std::shared_ptr<const VolumeGrid> volume(std::string_view id) const = 0;
};

}  // namespace skyfarm::assets

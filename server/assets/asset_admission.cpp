#include "server/assets/asset_admission.h"

#include <string>

#include "server/assets/asset_store.h"

namespace skyfarm::server {

std::vector<api::FieldError> missing_assets(const std::vector<ObjectSpec>& objects, const AssetStore* store) {
  std::vector<api::FieldError> errors;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const ObjectSpec& object = objects[i];
    if (object.shape != ShapeKind::kMesh) continue;
    if (store != nullptr && store->meta(object.asset)) continue;
    errors.push_back({"objects[" + std::to_string(i) + "].asset",
                      store != nullptr ? "no such asset on this server; upload the mesh first (POST /v1/assets)"
                                       : "this server has no asset store",
                      "\"" + object.asset + "\""});
  }
  return errors;
}

std::vector<api::FieldError> missing_volume_assets(const CloudsSpec& clouds, const AssetStore* store) {
  std::vector<api::FieldError> errors;
  for (std::size_t i = 0; i < clouds.volumes.size(); ++i) {
    const std::string& asset = clouds.volumes[i].asset;
    if (store != nullptr && store->meta(asset)) continue;
    errors.push_back({"clouds.volumes[" + std::to_string(i) + "].asset",
                      store != nullptr ? "no such asset on this server; upload the volume first (POST /v1/assets)"
                                       : "this server has no asset store",
                      "\"" + asset + "\""});
  }
  return errors;
}

}  // namespace skyfarm::server

// Admission of a request whose objects name mesh assets: every asset must be
// in the server's store before a job is made of it, or no worker could
// render it.  The errors name the field, as the request parser's do:
//   objects[2].asset: no such asset on this server; upload the mesh (POST /v1/assets), got "sha256:..."
#pragma once
#include <vector>

#include "api/field_error.h"
#include "common/clouds/cloud_spec.h"
#include "common/objects/object_spec.h"

namespace skyfarm::server {

class AssetStore;

// The errors for mesh objects whose asset `store` lacks (all of them when
// there is no store); empty when the request may be admitted.
std::vector<api::FieldError> missing_assets(const std::vector<ObjectSpec>& objects, const AssetStore* store);

// Likewise for the cloud volumes' assets (clouds.volumes[i].asset).
std::vector<api::FieldError> missing_volume_assets(const CloudsSpec& clouds, const AssetStore* store);

}  // namespace skyfarm::server

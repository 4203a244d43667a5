#include "api/probe_spec.h"

#include "common/core/constants.h"
#include "common/geometry/ray.h"

namespace skyfarm::api {

ProbeSpec probe_spec(const ProbeRequest& request) {
  ProbeSpec spec;
  spec.location = request.location;
  spec.time = request.time;
  spec.sun = request.sun;
  spec.atmosphere = request.atmosphere;
  spec.directions.reserve(request.directions.size());
  for (const auto& d : request.directions)
    spec.directions.push_back(direction_from_zenith_azimuth(d.zenith_deg * kDegToRad, d.azimuth_deg * kDegToRad));
  spec.wavelengths_nm = request.wavelengths_nm;
  spec.samples = request.samples;
  spec.seed = request.seed;
  spec.lut = request.method == Method::kLut;
  spec.unit_text_bytes = canonical_text(request).size();
  return spec;
}

}  // namespace skyfarm::api
